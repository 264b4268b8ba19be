"""The planner: every pulse group's timeline, and what each group must be loaded with next.

Each group (:func:`spec.registers.group_size` blocks pulsed together) keeps its place in the
frame (display position, dark or not), whether it is loaded and plays, the frame it shows (slot,
bit depth, entry settings: :mod:`.group_frames`) and its times (:mod:`.group_times`): when its
next pulse falls due, when its memory may change again (``t_rst + t_settle`` after its last
pulse, and no sooner than ``t_settle`` after RST_ACTIVE fell: :mod:`.reset_watch`) and when
RST_ACTIVE allows its next pulse. When the bus makes a pulse, the planner decides what follows
it: the group's next pulse time and its next load job, the next plane (a plane long enough to
hide the load, ``hide``) or clears ended by a dark pulse. At the last plane of a frame group 0
takes the newest complete frame, if one is offered (else the frame repeats). The frame control
starts, reloads and triggers the groups through command events.
"""

from amaranth import Array, Cat, Module, Mux, Signal
from amaranth.lib import data, stream, wiring
from amaranth.lib.wiring import In, Out

from spec.schedule import row_cycles

from ..registers import LSB_BITS, TIME_BITS, Registers, Source
from ..store.layouts import SLOT_BITS, FrameInfo, Showing
from .group_frames import GroupFrames
from .group_times import GroupTimes
from .layouts import COUNTER_BITS, event, group_bits, load_job
from .reset_watch import ResetWatch
from .timebase import exponent

__all__ = ["Planner", "Offer"]


class Offer(data.Struct):
    """The frame the store offers now: ``valid`` when it has a bit depth the sequencer plays;
    ``sequence`` when it is the next frame of a stored sequence (it does not replace a frame
    waiting for its trigger); ``showing``, its sequence entry's settings."""
    valid: 1
    slot: SLOT_BITS
    depth: 4
    sequence: 1
    showing: Showing


#: What the frame control's ``start`` begins: a frame, and whether it is the one offered.
START = data.StructLayout({"slot": SLOT_BITS, "depth": 4, "showing": Showing, "take": 1})


class Planner(wiring.Component):
    """Per-group timelines and load jobs.

    Parameters
    ----------
    dmd : :class:`spec.facts.DmdType`
    beats : int
        DCLK beats per cycle (a row cycle's length in cycles).

    Members
    -------
    regs : In(:class:`~gateware.registers.Registers`)
    now : In(TIME_BITS)
        The time base.
    n_groups : In(range(blocks + 1))
        Groups of the reset mode.
    rst_active : In(1)
        RST_ACTIVE, synchronised: with ``strict_rst``, no group's pulse is due while it is high.
    frames : In(stream.Signature(FrameInfo))
        The newest complete frame. A bit depth outside 1..8 is dropped when offered, and counted.
    offer : Out(Offer)
        The frame offered now, for the frame control.
    pulse : In(event(group))
        The bus made this group's pulse this cycle.
    loaded : In(event(group))
        The bus finished this group's load this cycle.
    start : In(event(START))
        Every group begins the frame ``slot`` of ``depth`` planes, shown as ``showing`` says, at
        its first plane; ``take``: that frame is the one offered, taken now.
    retake : In(event(newer, abandon, lead))
        A newer frame (``newer``: the one offered, taken now) or the same frame under new
        registers replaces what every group holds; each group's memory may change no sooner than
        ``lead``. ``abandon`` (the controller restarted): every group also leaves the frame it
        was playing and waits at its first plane.
    trigger : In(event(TIME_BITS))
        A trigger obeyed: group ``g``'s first pulse falls due at ``payload + g * stagger``.
    queue_first : In(event(group))
        Queue the group's first plane of the current frame.
    jobs : Out(event(load_job))
        Load jobs, in the order of the pulses that freed the groups (the queue always has room).
    due : Out(blocks)
        Bit g: group g is loaded, its pulse time has come and RST_ACTIVE allows it.
    imminent, imminent_clear : Out(1)
        A loaded group's pulse falls due within a row cycle, within a clear (and its no-op rows).
    writable : Out(blocks)
        Bit g: group g's memory may change (its settle time is over, counted from its pulse and
        from RST_ACTIVE's fall).
    all_ready : Out(1)
        Every group is loaded and waits for a trigger.
    playing : Out(1)
        Some group plays a frame.
    frame_start : Out(1)
        This cycle's pulse is the first of a frame.
    camera_start : Out(1)
        The same, for a frame whose entry pulses the camera.
    ended : Out(1)
        The last frame of a sequence played once has started; a frame taken anew (``start``,
        ``retake`` of a newer one) clears it.
    sync_out : Out(1)
        High while a frame is shown (first pulse to the last group's final dark pulse).
    frames_started, late, bad_frames : Out(COUNTER_BITS)
        Frames started; pulses made after their time; frames dropped for their bit depth.
    rst_late, rst_faults, rst_longest : Out(COUNTER_BITS)
        RST_ACTIVE falls later than planned; RST_ACTIVE missing after a pulse or stuck high; the
        longest RST_ACTIVE seen (:class:`~gateware.dlpc410.reset_watch.ResetWatch`).
    depth, lsb : Out(4), Out(LSB_BITS)
        The bit depth and the least significant plane's time of the frame the first group plays
        (or is about to).

    A frame's entry (:class:`~gateware.store.layouts.Showing`) sets its least significant
    plane's time, and for the frame after it (group 0: the one offered, if any, else its own
    again; the others: the one group 0 took) whether it follows without a trigger, after at
    least its dark time; the last frame of a sequence played once is followed by nothing.
    """

    def __init__(self, dmd, *, beats=1):
        self._dmd, self._beats = dmd, beats
        groups = dmd.blocks
        gb = group_bits(dmd)
        super().__init__({
            "regs": In(Registers),
            "now": In(TIME_BITS),
            "n_groups": In(range(groups + 1)),
            "rst_active": In(1),
            "frames": In(stream.Signature(FrameInfo)),
            "offer": Out(Offer),
            "pulse": In(event(gb)),
            "loaded": In(event(gb)),
            "start": In(event(START)),
            "retake": In(event(data.StructLayout({"newer": 1, "abandon": 1, "lead": TIME_BITS}))),
            "trigger": In(event(TIME_BITS)),
            "queue_first": In(event(gb)),
            "jobs": Out(event(load_job(dmd))),
            "due": Out(groups),
            "imminent": Out(1),
            "imminent_clear": Out(1),
            "writable": Out(groups),
            "all_ready": Out(1),
            "playing": Out(1),
            "frame_start": Out(1),
            "camera_start": Out(1),
            "ended": Out(1),
            "sync_out": Out(1),
            "frames_started": Out(COUNTER_BITS),
            "late": Out(COUNTER_BITS),
            "bad_frames": Out(COUNTER_BITS),
            "rst_late": Out(COUNTER_BITS),
            "rst_faults": Out(COUNTER_BITS),
            "rst_longest": Out(COUNTER_BITS),
            "depth": Out(4),
            "lsb": Out(LSB_BITS),
        })

    def elaborate(self, platform):
        m = Module()
        dmd, regs, now = self._dmd, self.regs, self.now
        R = row_cycles(dmd, self._beats)
        G = dmd.blocks
        use_prng = regs.source == Source.PRNG

        def per_group(shape, name, init=0):
            return Array(Signal(shape, name=f"{name}{g}", init=init) for g in range(G))
        pending = per_group(1, "pending")
        loaded = per_group(1, "loaded")
        pos = per_group(3, "pos")
        dark = per_group(1, "dark")
        m.submodules.frames = frames = GroupFrames(dmd)

        def lsb_of(frame):
            """The least significant plane's time of ``frame``."""
            return Mux(frame.showing.lsb != 0, frame.showing.lsb, regs.lsb)
        m.d.comb += [self.depth.eq(frames.first.depth), self.lsb.eq(lsb_of(frames.first))]
        active = Signal(G)
        for g in range(G):
            m.d.comb += active[g].eq(g < self.n_groups)

        m.submodules.reset_watch = watch = ResetWatch(dmd)
        m.d.comb += [watch.regs.eq(regs), watch.now.eq(now), watch.rst_active.eq(self.rst_active),
                     watch.pulse.valid.eq(self.pulse.valid), watch.pulse.payload.eq(self.pulse.payload),
                     self.rst_late.eq(watch.late), self.rst_faults.eq(watch.faults),
                     self.rst_longest.eq(watch.longest)]
        m.submodules.times = times = GroupTimes(dmd, soon=R, soon_clear=dmd.clear_row_cycles * R)
        m.d.comb += [times.regs.eq(regs), times.now.eq(now), times.active.eq(active),
                     times.trigger.valid.eq(self.trigger.valid), times.trigger.payload.eq(self.trigger.payload),
                     times.retake.valid.eq(self.retake.valid), times.retake.payload.eq(self.retake.payload.lead),
                     times.fell.valid.eq(watch.fell.valid), times.fell.payload.groups.eq(watch.fell.payload.groups),
                     times.fell.payload.settled.eq(watch.fell.payload.settled)]
        # ---- what the bus may do ----
        armed = [Signal(name=f"armed{g}") for g in range(G)]
        for g in range(G):
            # strict: no pulse while RST_ACTIVE may be high, by the plan or at the pin; loose: a
            # group's own reset only (RST_ACTIVE at the pin may be another group's; a group whose
            # reset has not ended is kept unloaded by the RST_ACTIVE watch, so it cannot pulse)
            rst_ok = Mux(regs.strict_rst, times.rst_over_any & ~self.rst_active, times.rst_over[g])
            m.d.comb += [
                armed[g].eq(active[g] & pending[g] & loaded[g]),
                self.due[g].eq(armed[g] & times.due[g] & rst_ok),
                self.writable[g].eq(times.memory_free[g] & ~watch.waiting[g]),
            ]
        m.d.comb += [
            self.imminent.eq(Cat(armed[g] & times.soon[g] for g in range(G)).any()),
            self.imminent_clear.eq(Cat(armed[g] & times.soon_clear[g] for g in range(G)).any()),
            self.all_ready.eq(Cat(~active[g] | (~pending[g] & loaded[g]) for g in range(G)).all()),
            self.playing.eq(Cat(active[g] & pending[g] for g in range(G)).any()),
        ]

        # ---- the frame offered ----
        depth_in = self.frames.payload.bit_depth
        frame_ok = (depth_in != 0) & (depth_in <= 8)
        m.d.comb += [self.offer.valid.eq(self.frames.valid & frame_ok),
                     self.offer.slot.eq(self.frames.payload.slot), self.offer.depth.eq(depth_in),
                     self.offer.sequence.eq(self.frames.payload.sequence),
                     self.offer.showing.eq(self.frames.payload.showing)]
        with m.If(self.frames.valid & ~frame_ok):
            m.d.comb += self.frames.ready.eq(1)
            m.d.sync += self.bad_frames.eq(self.bad_frames + 1)

        # ---- a load finished ----
        with m.If(self.loaded.valid):
            m.d.sync += loaded[self.loaded.payload].eq(1)

        # ---- a pulse: what follows it ----
        p = self.pulse.payload
        mine = frames.frame                    # the pulsed group's frame
        m.d.comb += [frames.group.eq(p), frames.offered.slot.eq(self.frames.payload.slot),
                     frames.offered.depth.eq(depth_in), frames.offered.showing.eq(self.frames.payload.showing)]
        pj, pdark, pdepth = pos[p], dark[p], mine.depth
        pe = exponent(m, regs, pj, pdepth, "pulse_exp")
        last = pj == pdepth - 1
        plane_len = Signal.like(regs.hide)
        m.d.comb += plane_len.eq(lsb_of(mine) << pe)
        # the frame after this one starts without a trigger: chained, or it follows (group 0
        # takes the one offered, if any); never after a sequence's last frame, nor hidden behind
        # a frame that wants dark time after it
        offered = (p == 0) & self.offer.valid & ~use_prng
        follow = Signal()
        m.d.comb += follow.eq((regs.chain | Mux(offered, self.offer.showing.follow, frames.next.showing.follow))
                              & ~mine.showing.last)
        pdark_time = mine.showing.dark
        hidden = ~pdark & (plane_len >= regs.hide) & (~last | (follow & (pdark_time == 0)))
        new_frame = last & (pdark | hidden)
        take = frames.take
        m.d.comb += take.eq(self.pulse.valid & new_frame & offered)
        with m.If(take):
            m.d.comb += self.frames.ready.eq(1)
        job = self.jobs.payload
        m.d.comb += [times.pulse.valid.eq(self.pulse.valid), times.pulse.payload.group.eq(p),
                     times.pulse.payload.delay.eq(
                         Mux(pdark, Mux(last & (pdark_time > regs.dark_gap), pdark_time, regs.dark_gap), plane_len))]
        with m.If(self.pulse.valid):
            with m.If(times.late):
                m.d.sync += self.late.eq(self.late + 1)
            m.d.sync += loaded[p].eq(0)
            m.d.comb += [self.jobs.valid.eq(1), job.group.eq(p), job.slot.eq(mine.slot),
                         job.depth.eq(pdepth), job.pos.eq(pj + 1)]
            with m.If(pdark | hidden):
                m.d.sync += [dark[p].eq(0), pos[p].eq(Mux(last, 0, pj + 1))]
                with m.If(last):
                    m.d.comb += [frames.advance.valid.eq(1), frames.advance.payload.eq(p),
                                 job.slot.eq(frames.coming.slot), job.depth.eq(frames.coming.depth), job.pos.eq(0)]
                    with m.If(pdark & ~follow):
                        m.d.sync += pending[p].eq(0)
            with m.Else():
                m.d.sync += dark[p].eq(1)
                m.d.comb += job.clear.eq(1)
            # frame boundaries: sync out, the frame counter
            with m.If((p == 0) & ~pdark & (pj == 0)):
                m.d.comb += [self.frame_start.eq(1), self.camera_start.eq(~frames.first.showing.camera_off)]
                m.d.sync += [self.sync_out.eq(1), self.frames_started.eq(self.frames_started + 1)]
                with m.If(frames.first.showing.last):
                    m.d.sync += self.ended.eq(1)
            with m.If((p == self.n_groups - 1) & pdark & last & ~follow):
                m.d.sync += self.sync_out.eq(0)

        # ---- commands of the frame control (a retake's frame over a start's) ----
        every = frames.every
        with m.If(self.start.valid):
            begin = self.start.payload
            with m.If(begin.take):
                m.d.comb += self.frames.ready.eq(1)
            m.d.comb += [every.valid.eq(1), every.payload.slot.eq(begin.slot), every.payload.depth.eq(begin.depth),
                         every.payload.showing.eq(begin.showing)]
            m.d.sync += self.ended.eq(0)
            for g in range(G):
                m.d.sync += [pos[g].eq(0), dark[g].eq(0)]
        with m.If(self.queue_first.valid):
            m.d.comb += [self.jobs.valid.eq(1), job.group.eq(self.queue_first.payload),
                         job.slot.eq(frames.next.slot), job.depth.eq(frames.next.depth), job.pos.eq(0), job.clear.eq(0)]
        with m.If(self.retake.valid):
            newer = self.retake.payload.newer
            with m.If(newer):
                m.d.comb += self.frames.ready.eq(1)
                m.d.sync += self.ended.eq(0)
            m.d.comb += [every.valid.eq(1),
                         every.payload.eq(Mux(newer, frames.offered.as_value(), frames.next.as_value()))]
            for g in range(G):
                m.d.sync += loaded[g].eq(0)
                with m.If(self.retake.payload.abandon):
                    m.d.sync += [pending[g].eq(0), pos[g].eq(0), dark[g].eq(0)]
            with m.If(self.retake.payload.abandon):
                m.d.sync += self.sync_out.eq(0)
        with m.If(self.trigger.valid):
            for g in range(G):
                with m.If(active[g]):
                    m.d.sync += pending[g].eq(1)
        return m
