"""The DLPC410 load/reset sequencer: PWM frames, phased and global pulses.

It plays the algorithm documented in :mod:`spec.schedule` (the model it must match cycle for
cycle): per pulse group a timeline of clocking pulses at exact cycles, loads queued in pulse
order and served behind the settle time, dark pulses of cleared blocks for short planes, and a
first plane preloaded so that a trigger becomes a pulse a few cycles later.

Its parts, joined by streams::

    frames --> Planner --jobs--> queue --> Requester --requests--> (store) --words--> RowSource
                 ^  ^   |                     |                                         |
                 |  |   |                     +--loads--> queue --> Bus <--beats--------+
                 |  |   +--dark jobs--------------------> queue --> Bus
                 |  +---- FrameControl
                 +-------- pulse, loaded ------------------------- Bus --> command pins

* :class:`~.planner.Planner`: every group's timeline; after a pulse, the group's next load job;
* :class:`~.control.FrameControl`: start, reload on a newer frame, obey or count triggers;
* :class:`~.requester.Requester`: load jobs to row requests, with the occupancy map;
* :class:`~.row_source.RowSource`: the store's words as beats, or the on-chip pattern source;
* :class:`~.bus.Bus`: every even free cycle, a due pulse, else a dark pulse's next clear, else the
  next row or clear, else nothing;
* :class:`~.camera.CameraTrigger`, :class:`~.light_gate.LightGate`, :class:`~.init.Init`,
  :class:`~.trigger.Trigger`.
"""

from amaranth import Cat, Module, Mux, Signal
from amaranth.lib import data, stream, wiring
from amaranth.lib.wiring import In, Out

from ..counter import Counter
from ..queue import Queue
from ..registers import Registers, ResetMode
from ..store.layouts import SLOT_BITS, FrameInfo, PlaneRequest
from . import interface
from .beat import cycle_lanes
from .bus import Bus
from .camera import CameraTrigger
from .control import FrameControl
from .init import TRAINING_EDGES, Init
from .layouts import Status, dark_load, group_span, load_job, ready_load
from .light_gate import LightGate
from .period_watch import PeriodWatch
from .planner import Planner
from .requester import Requester
from .row_source import RowSource
from .trigger import Trigger

__all__ = ["Sequencer", "Status"]


class Sequencer(wiring.Component):
    """DLPC410 sequencer for two-bus (DLP7000) and four-bus (DLP9500) DMDs.

    Parameters
    ----------
    dmd : :class:`spec.facts.DmdType`
        Geometry: a beat of ``bits_per_dclk`` bits per DCLK cycle (one 64-bit word on A/B, and
        a second on C/D for four buses), ``dclk_per_row`` beats per row; a block clear takes
        ``clear_row_cycles`` row cycles (1080p: the clear and two no-op rows; facts table).
    beats : int
        DCLK cycles per ``dmd`` cycle: 1 (DCLK = the ``dmd`` clock, 200 MHz) or 2 (400 MHz,
        through the platform's 4:1 serialisers). A row cycle is ``dclk_per_row // beats`` cycles.
    store_words : int
        64-bit words per transfer on ``words`` (1 or 2). A row loads every row cycle when the
        store keeps up with ``bits_per_dclk * beats / 64`` words a cycle; else the plan's
        ``row_period`` spaces the rows.

    Members
    -------
    pins : Out(:class:`gateware.dlpc410.interface.Signature`)
        The DLPC410 applications interface.
    regs : In(:class:`gateware.registers.Registers`)
        Run-time parameters. Change them only while ``at_rest`` is high, with ``reload``.
    at_rest : Out(1)
        No frame is playing and no load is under way: before the first frame, or every group
        loaded and waiting for a trigger (a chained run waits so only for its first trigger).
        The only time ``regs`` may change.
    reload : In(1)
        One cycle, while ``at_rest``, in the cycle ``regs`` change: every group's first plane is
        loaded again under the new registers (the reset mode and plane order decide what that
        is), as for a newer frame offered while waiting; a trigger in that cycle is an overrun.
    trigger_in, sync_in : In(1)
        TTL trigger and sync inputs (asynchronous).
    soft_trigger : In(1)
        Software trigger, a one-cycle pulse.
    sync_out : Out(1)
        High while a frame is shown (first pulse to the last group's final dark pulse).
    camera_out : Out(1)
        Camera trigger: ``camera_width`` cycles, starting ``camera_offset`` cycles after the
        frame's first clocking pulse appears on the pins.
    gate_out : Out(1)
        Light gate (:class:`~.light_gate.LightGate`): for a gated plane, high ``light_lead``
        cycles after its pulse appears on the pins, for the plane's ``light_times`` entry; high
        throughout while no plane is gated.
    ready : Out(1)
        A trigger (or sync pulse) now would be obeyed at once: every group holds its first plane
        and waits (the ready line a tiled display's sync master reads).
    frames : In(stream.Signature(FrameInfo))
        The newest complete frame; taken when a new frame is due (else the last one repeats),
        or, triggered and not chained, as soon as every group waits loaded for a trigger: the
        first plane is then loaded again from the new frame (a trigger meanwhile is an overrun).
        Each is shown as its sequence entry says (``showing``: exposure, dark time, follow,
        camera, last; all zero: as the registers say).
    requests : Out(stream.Signature(PlaneRequest))
        Rows to read, one block of one plane per request, in load order.
    words : In(stream.Signature(64 * store_words))
        The requested rows' words, in order, the first in the low bits.
    occ_slot : Out(SLOT_BITS), occupancy : In(ArrayLayout(8, blocks))
        Occupancy read port: per block a byte, bit k set when stored plane k has a bit set
        in the block, for slot ``occ_slot`` as it was one cycle earlier.
    seed, reseed : In(64), In(1)
        Seed of the Bernoulli pattern source.
    release : Out(stream.Signature(SLOT_BITS))
        A slot the sequencer will request no more rows from (every group has moved on to a
        frame in another slot); the store may reuse it once it has answered those requests.
    store_lost : In(1)
        The store lost its memory and has not recovered: the groups stop as when the DLPC410
        restarts (the loads under way dropped, the words owed taken as the store answers them),
        and start over once it has (what they hold then reads empty: dark).
    status : Out(Status)
    """

    def __init__(self, dmd, *, beats=1, store_words=1):
        assert dmd.buses in (2, 4) and dmd.bits_per_dclk == 32 * dmd.buses
        assert dmd.words_per_row * 64 == dmd.dclk_per_row * dmd.bits_per_dclk
        assert beats in (1, 2) and dmd.dclk_per_row % beats == 0 and dmd.dclk_per_row // beats >= 2
        self._dmd, self._beats, self._store_words = dmd, beats, store_words
        super().__init__({
            "pins": Out(interface.Signature(dmd.buses, beats)),
            "regs": In(Registers),
            "at_rest": Out(1),
            "reload": In(1),
            "trigger_in": In(1),
            "sync_in": In(1),
            "soft_trigger": In(1),
            "sync_out": Out(1),
            "camera_out": Out(1),
            "gate_out": Out(1),
            "ready": Out(1),
            "frames": In(stream.Signature(FrameInfo)),
            "requests": Out(stream.Signature(PlaneRequest)),
            "words": In(stream.Signature(64 * store_words)),
            "occ_slot": Out(SLOT_BITS),
            "occupancy": In(data.ArrayLayout(8, dmd.blocks)),
            "seed": In(64),
            "reseed": In(1),
            "release": Out(stream.Signature(SLOT_BITS)),
            "store_lost": In(1),
            "status": Out(Status),
        })

    def elaborate(self, platform):
        m = Module()
        dmd, regs, beats = self._dmd, self.regs, self._beats
        blocks = dmd.blocks

        m.submodules.init = init = Init()
        m.submodules.trigger = trig = Trigger()
        m.submodules.planner = planner = Planner(dmd, beats=beats)
        m.submodules.control = control = FrameControl(dmd, beats=beats)
        m.submodules.jobs = jobs = Queue(load_job(dmd), depth=blocks + 1)
        m.submodules.requester = requester = Requester(dmd)
        m.submodules.loads = loads = Queue(ready_load(dmd), depth=blocks + 1)
        m.submodules.darks = darks = Queue(dark_load(dmd), depth=blocks + 1)
        m.submodules.row_source = source = RowSource(dmd, beats=beats, store_words=self._store_words)
        m.submodules.bus = bus = Bus(dmd, beats=beats)
        m.submodules.camera = camera = CameraTrigger()
        m.submodules.light_gate = light_gate = LightGate()
        m.submodules.period_watch = period_watch = PeriodWatch()
        # the parts joined by streams, by name (the formal stream rules check each one's)
        self.parts = {"init": init, "planner": planner, "jobs": jobs, "requester": requester, "loads": loads,
                      "darks": darks, "row_source": source, "bus": bus, "control": control}
        m.d.comb += [
            init.ecp2_finished.eq(self.pins.ecp2_finished),
            init.init_active.eq(self.pins.init_active),
            init.rst_active.eq(self.pins.rst_active),
            trig.mode.eq(regs.trigger), trig.period.eq(regs.period), trig.run.eq(init.running),
            trig.pin.eq(self.trigger_in), trig.sync_in.eq(self.sync_in), trig.soft.eq(self.soft_trigger),
        ]

        # ---- the time base, and the groups of the reset mode ----
        m.submodules.time_base = time_base = Counter(len(self.status.now))
        m.d.comb += [time_base.inc.eq(init.running), self.status.now.eq(time_base.count)]
        n_groups = Signal(range(blocks + 1))
        size_log2 = Signal(3)
        with m.Switch(regs.reset_mode):
            with m.Case(ResetMode.GLOBAL):
                m.d.comb += n_groups.eq(1)
            with m.Case(ResetMode.QUAD):
                m.d.comb += [n_groups.eq((blocks + 3) // 4), size_log2.eq(2)]
            with m.Case(ResetMode.DUAL):
                m.d.comb += [n_groups.eq((blocks + 1) // 2), size_log2.eq(1)]
            with m.Case(ResetMode.SINGLE):
                m.d.comb += n_groups.eq(blocks)
        # (registered: the registers hold still while anything reads it)
        active = Signal(blocks)
        m.d.sync += active.eq(Cat(g < n_groups for g in range(blocks)))
        for part in (planner, control, requester, source, bus, camera, light_gate, period_watch):
            m.d.comb += part.regs.eq(regs)
        for part in (control, requester):
            m.d.comb += part.n_groups.eq(n_groups)

        # ---- frames, the planner and the frame control ----
        wiring.connect(m, wiring.flipped(self.frames), planner.frames)
        m.d.comb += [
            planner.active.eq(active),
            planner.rst_active.eq(init.rst_active_synced),
            planner.reload.eq(self.reload),
            control.all_ready.eq(planner.all_ready), control.trigger_ready.eq(planner.trigger_ready),
            control.counting.eq(init.running),
            control.initialised.eq(init.running & ~self.store_lost),
            control.strobe.eq(trig.strobe),
            control.reload.eq(self.reload),
            self.at_rest.eq(control.at_rest),
            self.ready.eq(control.ready),
            control.offer.eq(planner.offer),
            control.playing.eq(planner.playing),
            control.ended.eq(planner.ended),
            planner.trigger.eq(control.trigger),
            planner.lead_over.eq(control.lead_over),
        ]
        for name in ("start", "retake", "queue_first"):
            wiring.connect(m, getattr(control, name), getattr(planner, name))

        # ---- load jobs -> requester -> ready loads; row data ----
        self._split_jobs(m, planner.jobs, jobs.w_stream, darks.w_stream, size_log2)
        wiring.connect(m, jobs.r_stream, requester.jobs)
        m.d.comb += [requester.size_log2.eq(size_log2), requester.flushing.eq(control.flushing),
                     self.occ_slot.eq(requester.occ_slot), requester.occupancy.eq(self.occupancy)]
        wiring.connect(m, requester.requests, wiring.flipped(self.requests))
        wiring.connect(m, requester.release, wiring.flipped(self.release))
        wiring.connect(m, requester.loads, loads.w_stream)
        wiring.connect(m, wiring.flipped(self.words), source.words)
        m.d.comb += [
            source.asked.eq(self.requests.valid & self.requests.ready),
            source.flushing.eq(control.flushing),
            source.seed.eq(self.seed), source.reseed.eq(self.reseed),
        ]
        # (registered: the frame control's flush and restart wait on it)
        m.d.sync += control.drained.eq(requester.idle & ~planner.job_due & ~jobs.fill[0] & ~loads.fill[0]
                                       & ~darks.fill[0] & source.drained)

        # ---- the bus ----
        wiring.connect(m, loads.r_stream, bus.loads)
        wiring.connect(m, darks.r_stream, bus.darks)
        wiring.connect(m, source.beats, bus.beats)
        m.d.comb += [
            bus.even.eq(~time_base.count[0]),
            source.row_started.eq(bus.row_started),
            bus.row_ready.eq(source.row_ready),
            bus.running.eq(control.running), bus.flushing.eq(control.flushing),
            bus.hold.eq(control.retake.valid), bus.restart.eq(control.retake.valid),
            bus.rst_active.eq(init.rst_active_synced),
        ]
        wiring.connect(m, planner.bus, bus.planner)

        # ---- outputs and counters ----
        self._outputs(m, init, planner, control, bus, camera, light_gate, period_watch)
        self._drive_pins(m, init, bus)
        return m

    def _outputs(self, m, init, planner, control, bus, camera, light_gate, period_watch):
        """The camera, gate, sync and status outputs: the frame's marks to the camera trigger and
        the period watch, the planes' pulses to the light gate, and every part's counters to
        ``status``."""
        m.d.comb += [
            camera.frame_start.eq(planner.camera_start),
            light_gate.pulse.eq(planner.light_pulse), light_gate.exponent.eq(planner.light_exponent),
            self.gate_out.eq(light_gate.out),
            period_watch.frame_start.eq(planner.frame_start), period_watch.depth.eq(planner.depth),
            period_watch.lsb.eq(planner.lsb),
            self.camera_out.eq(camera.out),
            self.sync_out.eq(planner.sync_out),
            self.status.frames.eq(planner.frames_started),
            self.status.late.eq(planner.late),
            self.status.rst_late.eq(planner.rst_late),
            self.status.rst_faults.eq(planner.rst_faults),
            self.status.restarts.eq(init.restarts),
            self.status.rst_longest.eq(planner.rst_longest),
            self.status.period_short.eq(period_watch.short),
            self.status.bad_frames.eq(planner.bad_frames),
            self.status.triggers.eq(control.triggers),
            self.status.overruns.eq(control.overruns),
            self.status.early.eq(control.early),
            self.status.held.eq(control.held),
            self.status.after_end.eq(control.after_end),
            self.status.underruns.eq(bus.underruns),
        ]

    def _split_jobs(self, m, jobs, planes, darks, size_log2):
        """The planner's ``jobs`` to the plane jobs' queue (``planes``, the requester's) and a dark
        pulse's clears to their own (``darks``, the bus's: they need no data), with the group's
        blocks. The queues always have room: one job per group in flight, first planes only once
        the queue is empty."""
        job = jobs.payload
        dark = darks.payload
        first, last = group_span(self._dmd, self.regs.reset_mode, size_log2, job.group)
        m.d.comb += [planes.valid.eq(jobs.valid & ~job.clear), planes.payload.eq(job),
                     darks.valid.eq(jobs.valid & job.clear),
                     dark.group.eq(job.group), dark.first.eq(first), dark.last.eq(last)]

    def _drive_pins(self, m, init, bus):
        """The DLPC410's pins: the static ones from the registers, then the training pattern while
        the controller initialises, else the bus's row cycles."""
        dmd, regs, beats, pins = self._dmd, self.regs, self._beats, self.pins
        edges = 2 * beats
        m.d.comb += [pins.arstz.eq(1), pins.wdt_enblz.eq(1), pins.comp_data.eq(0),
                     pins.ns_flip.eq(regs.ns_flip), pins.pwr_float.eq(regs.park)]
        with m.If(init.training):
            # the pattern's four edges span two DCLK cycles: one dmd cycle at two beats, two
            # cycles at one beat (the phase alternates); every data pin and DVALID carry it
            phase = Signal()
            m.d.sync += phase.eq(~phase)
            for e in range(edges):
                bit = Mux(phase, TRAINING_EDGES[(e + 2) % 4], TRAINING_EDGES[e]) if beats == 1 else TRAINING_EDGES[e]
                for bus_name in "abcd"[:dmd.buses]:
                    m.d.comb += getattr(pins, f"din_{bus_name}")[e].eq(Mux(bit, 0xFFFF, 0))
                m.d.comb += pins.dvalid[e].eq(bit)
            m.d.comb += pins.rst2blkz.eq(1)
        with m.Else():
            for bus_name, edge, first_bit in cycle_lanes(dmd.buses, beats):
                m.d.comb += getattr(pins, f"din_{bus_name.lower()}")[edge].eq(bus.beat[first_bit:first_bit + 16])
            cmd = bus.command
            m.d.comb += [pins.dvalid.eq(bus.dvalid.replicate(edges)), pins.rowmd.eq(cmd.rowmd),
                         pins.rowad.eq(cmd.rowad), pins.blkmd.eq(cmd.blkmd), pins.blkad.eq(cmd.blkad),
                         pins.rst2blkz.eq(cmd.rst2blkz)]
