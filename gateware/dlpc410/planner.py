"""The planner: every pulse group's timeline, and what each group must be loaded with next.

Each group (:func:`spec.registers.group_size` blocks pulsed together) keeps its place in the
frame (display position, dark or not), whether it is loaded and plays, the frame it shows
(:mod:`.group_frames`) and its times (:mod:`.group_times`); :mod:`.plane_info` works out ahead
what each group's next pulse does (the plane's length against ``hide``, the time to the pulse
after it), :mod:`.reset_watch` watches RST_ACTIVE, :mod:`.frame_offer` registers the store's
offer and :mod:`.load_jobs` forms the load jobs.

The bus decides a pulse (``choice``) from flags the planner registered the cycle before
(``due``, ``imminent``, ``writable``); on that cycle the planner decides what the pulse does
(from its registered answers and the frame offered) and registers it, and applies it on the
next cycle: the group's position, frame, dark and pending flags, its times, the frame taken. The
load job for the group's next plane follows a cycle later, from the group's new state. A frame
control event (a start, a retake, a trigger obeyed, a first plane queued) comes registered and
is applied on its cycle.

``playing`` and ``ended`` are as the decisions made so far leave them (a pulse being applied is
counted in), for the frame control, which counts in its own.
"""

from amaranth import Module, Mux, Signal
from amaranth.lib import data, stream, wiring
from amaranth.lib.wiring import In, Out

from spec.schedule import row_cycles

from ..counter import Counter
from ..registers import LSB_BITS, PlaneOrder, Registers, Source
from ..store.layouts import SLOT_BITS, FrameInfo, Showing
from .due import fours_of, lowest_due_has
from .frame_offer import FrameOffer, Offer
from .group_frames import GroupFrames
from .group_times import GroupTimes
from .layouts import COUNTER_BITS, PulseSignature, event, group_bits, load_job
from .load_jobs import LoadJobs
from .plane_info import PlaneInfo
from .reset_watch import ResetWatch

__all__ = ["Planner", "START"]


#: What the frame control's ``start`` begins: a frame, and whether it is the one offered.
START = data.StructLayout({"slot": SLOT_BITS, "depth": 4, "low_plane": 3, "showing": Showing, "take": 1})


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
    active : In(blocks)
        Bit g: group g is one of the reset mode's.
    rst_active : In(1)
        RST_ACTIVE, synchronised.
    reload : In(1)
        The registers change in this cycle.
    frames : In(stream.Signature(FrameInfo))
        The newest complete frame. A bit depth outside 1..8, or one the plane order cannot show,
        is dropped when offered, and counted.
        A frame taken is answered (``ready``) the cycle after it was taken.
    offer : Out(Offer)
        The frame offered, as the store offered it the cycle before
        (:data:`spec.schedule.OFFER_LAG`), for the frame control: ``valid`` unless a group's take
        of it is answered now (a start or retake the frame control applies now is its own to
        count in).
    bus : Out(PulseSignature(blocks))
        To the bus, registered: which groups are due, may be written, free soon, and whether a
        pulse is imminent; back from it: this cycle's decision (``choice``, ``pulsing``) and the
        loads that end (``loaded``).
    start : In(event(START))
        Every group begins the frame ``slot`` of ``depth`` planes from stored plane ``low_plane``,
        shown as ``showing`` says, at its first plane; ``take``: that frame is the one offered.
    retake : In(event(newer, abandon))
        A newer frame (``newer``: the one offered) or the same frame under new registers replaces
        what every group holds. ``abandon`` (the controller restarted): every group also leaves
        the frame it was playing and waits at its first plane.
    trigger : In(1)
        A trigger obeyed: every active group's first pulse falls due (group 0 the cycle after
        next, the others ``stagger`` apart).
    queue_first : In(event(group))
        Queue the group's first plane of the current frame.
    lead_over : In(1)
        The frame control lets the memory change by the next cycle (a retake's lead, the first
        loads' wait after initialisation).
    jobs : Out(event(load_job))
        Load jobs, in the order of the pulses that freed the groups (the queue always has room).
    pending, holds : Out(blocks)
        Bit g: group g plays a frame; is loaded with the plane (or dark) its next pulse shows.
    all_ready : Out(1)
        Every group of the reset mode is loaded and waits for a trigger (registered: as this
        cycle's state is; the frame control counts in its own decisions).
    trigger_ready : Out(1)
        A trigger may be obeyed (registered, as ``all_ready``): no group of the reset mode plays,
        and every one is loaded, or in ``GROUPS`` with group 0 offset (the first to pulse, its
        offset room for the bus to end an operation under way) group 0 with RST_ACTIVE allowing
        its pulse: each other group's first load is under way and due by its own offset.
    job_due : Out(1)
        A load job is on its way (it is written within three cycles).
    playing : Out(1)
        Some group plays a frame.
    ended : Out(1)
        The last frame of a sequence played once has started; a frame taken anew (``start``,
        ``retake`` of a newer one) clears it.
    frame_start, camera_start : Out(1)
        The pulse applied now is the first of a frame (that pulses the camera).
    light_pulse, light_exponent : Out(1), Out(3)
        Group 0's pulse applied now shows a plane (not a dark pulse), of that weight exponent
        (for the light gate: gating is global, one group).
    sync_out : Out(1)
        High while a frame is shown, with the pins (group 0's first pulse to the final dark pulse
        of the last group to end).
    frames_started, late, bad_frames : Out(COUNTER_BITS)
        Frames started; pulses made after their time; frames dropped for their bit depth.
    rst_late, rst_faults, rst_longest : Out(COUNTER_BITS)
        RST_ACTIVE falls later than planned; RST_ACTIVE missing after a pulse or stuck high; the
        longest RST_ACTIVE seen (:class:`~gateware.dlpc410.reset_watch.ResetWatch`).
    depth, lsb : Out(4), Out(LSB_BITS)
        The bit depth and the least significant plane's time of the frame the first group plays
        (or is about to).

    A frame's entry (:class:`~gateware.store.layouts.Showing`) sets its least significant
    plane's time, and for the frame after it (the first group to move on: the one offered, if
    any, else its own again; the others: the one it took) whether it follows without a trigger,
    after at least its dark time; the last frame of a sequence played once is followed by
    nothing.
    """

    def __init__(self, dmd, *, beats=1):
        self._dmd, self._beats = dmd, beats
        blocks = dmd.blocks
        gb = group_bits(dmd)
        super().__init__({
            "regs": In(Registers),
            "active": In(blocks),
            "rst_active": In(1),
            "reload": In(1),
            "frames": In(stream.Signature(FrameInfo)),
            "offer": Out(Offer),
            "bus": Out(PulseSignature(blocks)),
            "start": In(event(START)),
            "retake": In(event(data.StructLayout({"newer": 1, "abandon": 1}))),
            "trigger": In(1),
            "queue_first": In(event(gb)),
            "lead_over": In(1),
            "jobs": Out(event(load_job(dmd))),
            "pending": Out(blocks),
            "holds": Out(blocks),
            "all_ready": Out(1),
            "trigger_ready": Out(1),
            "job_due": Out(1),
            "playing": Out(1),
            "ended": Out(1),
            "frame_start": Out(1),
            "camera_start": Out(1),
            "light_pulse": Out(1),
            "light_exponent": Out(3),
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
        dmd, regs = self._dmd, self.regs
        cycles_per_row = row_cycles(dmd, self._beats)
        blocks = dmd.blocks
        use_prng = regs.source == Source.PRNG
        active = self.active

        pending, loaded, dark = self.pending, self.holds, Signal(blocks)
        pos = [Signal(3, name=f"pos{g}") for g in range(blocks)]
        m.submodules.frames = frames = GroupFrames(dmd)
        m.d.comb += frames.active.eq(active)
        m.submodules.info = info = PlaneInfo(dmd)
        m.submodules.times = times = GroupTimes(dmd, soon=cycles_per_row,
                                                soon_clear=dmd.clear_row_cycles * cycles_per_row)
        m.submodules.reset_watch = watch = ResetWatch(dmd)
        m.d.comb += [info.regs.eq(regs), times.regs.eq(regs), watch.regs.eq(regs),
                     watch.rst_active.eq(self.rst_active), times.active.eq(active),
                     self.rst_late.eq(watch.late), self.rst_faults.eq(watch.faults),
                     self.rst_longest.eq(watch.longest)]
        for g in range(blocks):
            m.d.comb += [info.pos[g].eq(pos[g]), info.frame[g].eq(frames.frame[g]),
                         times.delay[g].eq(info.delay[g])]
        m.d.comb += info.dark.eq(dark)
        first = frames.frame[0]
        m.d.comb += [self.depth.eq(first.depth),
                     self.lsb.eq(first.showing.lsb_or(regs.lsb))]

        # ---- the frame offered: taken by a group (last cycle), or by a start or retake now ----
        offer, taking = self._offered(m, frames)

        # ---- the decision: what the pulse the bus chooses does (registered) ----
        pulse = self.bus.choice
        usable = offer.valid & ~use_prng
        # (the first group to move on to a new frame takes the one offered: ``frames.first``)
        hidden, final, takes = self._outcomes(
            m, info, frames, dark, usable, frames.first)
        decided = Signal(blocks)                    # the pulse decided last cycle, applied now
        decided_any = Signal()
        moves, ends_play, take, starts, camera, ends_seq, late_now = (
            Signal(blocks), Signal(blocks), Signal(), Signal(), Signal(), Signal(), Signal(blocks))
        ends_fours = Signal(-(-blocks // 4))        # bit q: some bit of ``ends_play[4q:4q + 4]``
        ends_any = ends_fours.any()
        first_plane = ~dark[0] & (pos[0] == 0)
        ending = pulse & final                     # the pulse decided ends its group's play
        m.d.sync += [
            decided.eq(pulse), decided_any.eq(self.bus.pulsing),
            # (read only with ``decided``: no need to wait for the choice)
            moves.eq(dark | hidden),
            ends_play.eq(ending),
            # (by fours: whether the pulse applied ends a play is then no OR over every group)
            ends_fours.eq(fours_of(ending)),
            # (the bus pulses the lowest due group: whether that group takes is asked of the due
            # flags themselves, the bus's gating added last, a shallower path than through pulse)
            take.eq(self.bus.pulsing & usable & lowest_due_has(self.bus.due, self.bus.due_fours, takes)),
            starts.eq(pulse[0] & first_plane),
            camera.eq(pulse[0] & first_plane & ~first.showing.camera_off),
            ends_seq.eq(pulse[0] & first_plane & first.showing.last),
            late_now.eq(times.late),
        ]
        m.d.comb += taking.eq(take)

        # ---- the pulse, applied (a load that ends now first) ----
        load_ends = self.bus.loaded
        m.d.sync += loaded.eq(loaded | load_ends)
        every = frames.every
        m.d.comb += [frames.take.eq(take), times.pulse.eq(decided), times.pulse_any.eq(decided_any),
                     watch.pulse.eq(decided), watch.pulse_any.eq(decided_any),
                     info.changed.eq(decided | Mux(every.valid, (1 << blocks) - 1, 0)),
                     self.frame_start.eq(starts), self.camera_start.eq(camera),
                     self.light_pulse.eq(decided[0] & ~dark[0]), self.light_exponent.eq(info.exponent)]
        for g in range(blocks):
            with m.If(decided[g]):
                m.d.sync += loaded[g].eq(0)
                with m.If(moves[g]):
                    m.d.sync += [dark[g].eq(0), pos[g].eq(Mux(info.last[g], 0, pos[g] + 1))]
                    m.d.comb += frames.advance[g].eq(info.last[g])
                with m.Else():
                    m.d.sync += dark[g].eq(1)
        # ---- the frame's marks and the counters ----
        abandon = self.retake.valid & self.retake.payload.abandon
        ended = self._frame_marks(m, starts, ends_any, ends_seq, abandon, late=(decided & late_now).any())

        # ---- the load job, from the group's new state (and a first plane queued) ----
        jobs = self._load_jobs(m, frames, pos, dark, decided, decided_any)

        # ---- the frame control's events ----
        with m.If(self.start.valid):
            begin = self.start.payload
            m.d.comb += [every.valid.eq(1), every.payload.slot.eq(begin.slot), every.payload.depth.eq(begin.depth),
                         every.payload.low_plane.eq(begin.low_plane), every.payload.showing.eq(begin.showing)]
            m.d.sync += [dark.eq(0)] + [pos[g].eq(0) for g in range(blocks)]
        with m.If(self.retake.valid):
            newer = self.retake.payload.newer
            m.d.comb += [every.valid.eq(1),
                         every.payload.eq(Mux(newer, frames.offered.as_value(), frames.next.as_value()))]
            m.d.sync += loaded.eq(0)
            with m.If(abandon):
                m.d.sync += [dark.eq(0)] + [pos[g].eq(0) for g in range(blocks)]
        m.d.comb += [times.obey.eq(self.trigger), times.abandon.eq(abandon)]
        # (a trigger sets the groups of the mode playing; the registers change only while none
        # plays, so no group outside the mode ever plays)
        pending_next = Signal(blocks)
        m.d.comb += pending_next.eq(Mux(self.trigger, pending | active, Mux(abandon, 0, pending & ~ends_play)))
        m.d.sync += pending.eq(pending_next)

        # ---- as the decisions so far leave them ----
        m.d.comb += [
            self.playing.eq(self._playing(m, abandon, ends_any)),
            self.ended.eq(ended | ends_seq),
            self.job_due.eq(jobs.due),
        ]
        self._ready_flags(m, times, decided)

        # ---- what the bus may do next cycle (registered) ----
        self._bus_flags(m, times, info, watch, decided)
        return m

    def _offered(self, m, frames):
        """The store's offer, registered (:class:`~.frame_offer.FrameOffer`), for the frame control
        and the groups' ``frames``: answered when a group took it the cycle before, or a start or
        a retake of a newer frame takes it now. Returns the offer and ``taking``, which the caller
        drives (a group took the offered frame the cycle before)."""
        m.submodules.offers = offers = FrameOffer(self._dmd.blocks)
        wiring.connect(m, wiring.flipped(self.frames), offers.frames)
        m.d.comb += [offers.regs.eq(self.regs), offers.active.eq(self.active), offers.reload.eq(self.reload)]
        taking = Signal()                      # a group took the offered frame last cycle
        m.d.comb += [offers.answered.eq(taking | (self.start.valid & self.start.payload.take)
                                        | (self.retake.valid & self.retake.payload.newer)),
                     self.offer.eq(offers.offer), self.offer.valid.eq(offers.held & ~taking),
                     self.bad_frames.eq(offers.bad_frames),
                     frames.offered.slot.eq(offers.offer.slot), frames.offered.depth.eq(offers.offer.depth),
                     frames.offered.low_plane.eq(offers.offer.low_plane),
                     frames.offered.showing.eq(offers.offer.showing)]
        return offers.offer, taking

    def _load_jobs(self, m, frames, pos, dark, decided, decided_any):
        """The load jobs (:class:`~.load_jobs.LoadJobs`), from each group's ``frames``, display
        position ``pos`` and ``dark`` flag as the pulse applied now (``decided``, ``decided_any``)
        leaves them, and the first planes queued. Returns the part, whose ``due`` the frame
        control reads."""
        m.submodules.load_jobs = jobs = LoadJobs(self._dmd)
        wiring.connect(m, wiring.flipped(self.queue_first), jobs.queue_first)
        wiring.connect(m, jobs.jobs, wiring.flipped(self.jobs))
        m.d.comb += [jobs.regs.eq(self.regs), jobs.pulse.eq(decided), jobs.pulse_any.eq(decided_any),
                     jobs.dark.eq(dark), jobs.next.eq(frames.next)]
        for g in range(self._dmd.blocks):
            m.d.comb += [jobs.pos[g].eq(pos[g]), jobs.frame[g].eq(frames.frame[g])]
        return jobs

    def _frame_marks(self, m, starts, ends_any, ends_seq, abandon, *, late):
        """``sync_out`` (high from a frame's first pulse, ``starts``, until the last group's play
        ends, ``ends_any``, or the groups abandon their frames), the frames started and the late
        pulses counted (``late``: the pulse applied now is late, counted a cycle later), and
        ``ended`` (returned, registered: a sequence played once reached its last frame,
        ``ends_seq``; a frame taken anew clears it)."""
        m.submodules.started = started = Counter(COUNTER_BITS)
        m.submodules.late_count = late_count = Counter(COUNTER_BITS)
        was_late = Signal()                    # (counted a cycle later)
        m.d.sync += was_late.eq(late)
        m.d.comb += [started.inc.eq(starts), self.frames_started.eq(started.count),
                     late_count.inc.eq(was_late), self.late.eq(late_count.count)]
        ended = Signal()
        with m.If(starts):
            m.d.sync += self.sync_out.eq(1)
        # (the last group to end its play: in GROUPS, whichever it is; ``playing`` is worked out
        # from the groups that played the cycle before)
        with m.If(ends_any & ~self.playing):
            m.d.sync += self.sync_out.eq(0)
        with m.If(ends_seq):
            m.d.sync += ended.eq(1)
        with m.If(self.start.valid):
            m.d.sync += ended.eq(0)
        with m.If(self.retake.valid):
            with m.If(self.retake.payload.newer):
                m.d.sync += ended.eq(0)
            with m.If(abandon):
                m.d.sync += self.sync_out.eq(0)
        return ended

    def _ready_flags(self, m, times, decided):
        """``all_ready`` and ``trigger_ready``, registered from this cycle's changes: a trigger or
        a retake makes them false; else each group of the mode neither playing nor pulsing now
        (a pulse only changes a group that plays) and loaded (or its load ends now); for a
        trigger in GROUPS, group 0 alone loaded, and RST_ACTIVE allowing its pulse (the others'
        last pulses may be recent), if its offset leaves the bus time to end what it does when
        the trigger comes (else every group, the bus idle). ``decided``: the pulse applied now."""
        blocks, active, regs = self._dmd.blocks, self.active, self.regs
        pending, loaded, load_ends = self.pending, self.holds, self.bus.loaded
        waits = ~self.trigger & ~self.retake.valid & (~active | (~pending & ~decided)).all()
        groups = Signal()               # (the registers hold still long before a trigger)
        m.d.sync += groups.eq((regs.order == PlaneOrder.GROUPS) & (regs.group_offsets[0] != 0))
        spared = Mux(groups, ((1 << blocks) - 1) & ~1, 0)
        m.d.sync += [self.all_ready.eq(waits & (~active | loaded | load_ends).all()),
                     self.trigger_ready.eq(waits & (~active | loaded | load_ends | spared).all()
                                           & (~groups | times.rst_over[0]))]

    def _playing(self, m, abandon, ends_any):
        """Some group plays, as the pulse applied now leaves it, from a count of the groups that
        play (``pending``'s bits) kept as a thermometer code, so that no sum or OR runs over the
        groups: a trigger sets every group of the mode playing (none did: it is obeyed only
        then; ``active`` is itself the thermometer code of their number), ``abandon`` none, and
        a pulse that ends its group's play (``ends_any``; one pulse at a time, of a group that
        plays) one fewer. Some group plays if two do, or if one does and the pulse applied now
        does not end its play."""
        blocks = self._dmd.blocks
        plays = Signal(blocks)                      # bit i: more than i groups play
        m.d.sync += plays.eq(Mux(self.trigger, self.active, Mux(abandon, 0, Mux(ends_any, plays >> 1, plays))))
        return (plays[1] if blocks > 1 else 0) | (plays[0] & ~ends_any)

    def _bus_flags(self, m, times, info, watch, decided):
        """The flags the bus decides from next cycle, registered: ``due``, ``imminent``,
        ``imminent_clear``, ``writable``, ``frees_soon`` (group by group, each one function of its group's
        registered state and its ``times``, ``info`` and ``watch`` flags; ``decided``: the pulse
        applied now)."""
        blocks, active = self._dmd.blocks, self.active
        pending, loaded, load_ends = self.pending, self.holds, self.bus.loaded
        armed = active & pending & ~decided & (loaded | load_ends)
        ready_now = times.rst_over & info.fresh
        due = Signal(blocks)
        m.d.comb += due.eq((armed & times.due & ready_now)
                           | Mux(self.trigger, times.at_once & (loaded | load_ends) & ready_now, 0))
        # (and none in the cycle a retake is applied: the lead's countdown loads then)
        writable = (times.settled & watch.free & ~decided
                    & Mux(self.lead_over & ~self.retake.valid, (1 << blocks) - 1, 0))
        m.d.sync += [
            self.bus.due.eq(due), self.bus.due_fours.eq(fours_of(due)),
            self.bus.imminent.eq((armed & times.soon).any()),
            self.bus.imminent_clear.eq((armed & times.soon_clear).any()),
            self.bus.writable.eq(writable),
            # (writable too: the bus then asks one flag whether the dark's clears go first or
            # are about to)
            self.bus.frees_soon.eq(writable | (times.frees_soon & ~decided)),
            self.bus.frees_soon_clear.eq(writable | (times.frees_soon_clear & ~decided)),
        ]

    def _outcomes(self, m, info, frames, dark, usable, first):
        """What each group's next pulse does: ``hidden`` (bit g: it shows a plane and the next
        one is loaded behind it), ``final`` (bit g: its dark pulse ends the group's play), and
        whether it takes the frame offered, if ``usable`` (it is the ``first`` group to move on
        to a new frame): bit g of ``takes``, at its frame's last dark pulse, or at a last plane
        that hides the next frame's first if the frame offered follows (one lookup by the
        lowest due group, not two)."""
        regs, blocks = self.regs, self._dmd.blocks
        offered_follow = self.offer.showing.follow
        hidden, final, takes = Signal(blocks), Signal(blocks), Signal(blocks)
        followed = regs.chain | offered_follow
        for g in range(blocks):
            # the frame after this one starts without a trigger: chained, or it follows (the
            # first group to move on takes the one offered, if any); never after a sequence's
            # last frame
            ends_sequence = frames.frame[g].showing.last
            follows_next = (regs.chain | frames.next.showing.follow) & ~ends_sequence
            follows_offered = (regs.chain | offered_follow) & ~ends_sequence
            follow = Mux(usable & first[g], follows_offered, follows_next)
            # the next plane is loaded behind this one; at a frame's end only if the frame after
            # follows and this one wants no dark time
            m.d.comb += [
                hidden[g].eq((~dark[g] & info.big[g] & ~info.last[g])
                             | (~dark[g] & info.big[g] & info.keeps_dark[g] & follow)),
                final[g].eq(dark[g] & info.last[g] & ~follow),
            ]
            # the first group takes the frame offered at its frame's last pulse, dark or hiding
            # the next (which, being the offered frame's first plane, follows as the offered
            # frame says). The group's own flags are registered: they change only when it
            # pulses, and it pulses again only once its plane information is fresh, a cycle
            # after which they are too (``first`` changes as the others move on: not registered)
            at_dark, may_hide = Signal(name=f"takes_dark{g}"), Signal(name=f"takes_hiding{g}")
            m.d.sync += [at_dark.eq(info.last[g] & dark[g]),
                         may_hide.eq(info.last[g] & info.big[g] & info.keeps_dark[g] & ~ends_sequence)]
            m.d.comb += takes[g].eq(first[g] & (at_dark | (may_hide & followed)))
        return hidden, final, takes
