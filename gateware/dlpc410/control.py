"""The frame control: when the groups start, take a newer frame, reload, and obey a trigger.

States: ``WAIT`` for the first frame (or the pattern source), ``QUEUE`` every group's first
plane, ``RUN``; a newer frame offered while no group plays (or new registers at rest) is taken at
once and every group's first plane loaded again from it (``RELOAD``), after ``FLUSH`` when stale
loads were under way: they are dropped, the words already asked of the store discarded, and the
new loads start exactly ``flush_rows * row_period`` cycles after the frame was taken (the
schedule model uses the same time). A newer frame does not delay a trigger: while the triggers
come at a steady pace (the last two an interval apart, the next not yet an eighth of an interval
overdue), it replaces the waiting frame only if the reload ends before the next trigger is due
(:func:`spec.schedule.reload_bound`), else it is shown at the trigger after. A trigger is obeyed
when every group is loaded and waits; otherwise it is an overrun (or early, before the groups
run).

A controller that initialises again (``initialised`` falls: INIT_ACTIVE high again, or
ECP2_FINISHED low; or the store lost its memory) has lost the DMD's memory: ``RESTART`` stops
every pulse and load, drops the loads under way as ``FLUSH`` does, and once the controller is
ready again every group starts over from its first plane (of the newest frame) as after a
reload, no sooner than ``init_to_dvalid`` clocks later; the groups then wait for a trigger.
"""

from amaranth import Module, Mux, Signal
from amaranth.lib import data, wiring
from amaranth.lib.wiring import In, Out

from spec.schedule import INIT_TO_DVALID, flush_rows, reload_cycles, row_cycles

from ..registers import DURATION_BITS, TIME_BITS, Registers, Source, TriggerMode
from .layouts import COUNTER_BITS, event, group_bits
from .planner import START, Offer
from .timebase import diff

__all__ = ["FrameControl"]


class FrameControl(wiring.Component):
    """Starts, reloads and triggers the planner's groups.

    Parameters
    ----------
    dmd : :class:`spec.facts.DmdType`
    beats : int
        DCLK beats per cycle (a row cycle's length in cycles).

    Members
    -------
    regs : In(Registers)
    now : In(TIME_BITS)
    n_groups : In(range(blocks + 1))
    initialised : In(1)
        The DLPC410 is initialised and the store holds its frames (it may fall again: the
        controller restarts, or the DDR2 loses its calibration).
    strobe : In(1)
        A trigger (from :class:`~gateware.dlpc410.trigger.Trigger`).
    reload : In(1)
        New registers this cycle (only while ``at_rest``): load every group's first plane again.
    at_rest : Out(1)
        No frame plays and no load is under way: before the first frame, or every group loaded
        and waiting for a trigger.
    offer : In(:class:`~gateware.dlpc410.planner.Offer`)
        The frame the store offers.
    all_ready, playing, ended : In(1)
        From the planner.
    drained : In(1)
        No load job queued or looked up, and no word owed by the store.
    start, retake, trigger, queue_first : Out(event)
        The planner's commands (see :class:`~gateware.dlpc410.planner.Planner`).
    running : Out(1)
        The groups run (pulses and loads may be made).
    ready : Out(1)
        A trigger now would be obeyed at once: a frame is loaded in every group, none plays, no
        newer frame is being taken and no trigger is held (a sync master's ready line).
    flushing : Out(1)
        Stale loads are being dropped.
    triggers, overruns, early, held, after_end : Out(COUNTER_BITS)
        Triggers obeyed; ignored because a frame played or was not loaded yet (and one was held
        already, or ``trigger_hold`` is low); before the groups ran (or while the controller
        restarts); held until every group was ready (``trigger_hold``); ignored because a
        sequence played once had ended.
    """

    def __init__(self, dmd, *, beats=1):
        self._dmd, self._beats = dmd, beats
        gb = group_bits(dmd)
        super().__init__({
            "regs": In(Registers),
            "now": In(TIME_BITS),
            "n_groups": In(range(dmd.blocks + 1)),
            "initialised": In(1),
            "strobe": In(1),
            "reload": In(1),
            "at_rest": Out(1),
            "offer": In(Offer),
            "all_ready": In(1),
            "playing": In(1),
            "ended": In(1),
            "drained": In(1),
            "start": Out(event(START)),
            "retake": Out(event(data.StructLayout({"newer": 1, "abandon": 1, "lead": TIME_BITS}))),
            "trigger": Out(event(TIME_BITS)),
            "queue_first": Out(event(gb)),
            "running": Out(1),
            "ready": Out(1),
            "flushing": Out(1),
            "triggers": Out(COUNTER_BITS),
            "overruns": Out(COUNTER_BITS),
            "early": Out(COUNTER_BITS),
            "held": Out(COUNTER_BITS),
            "after_end": Out(COUNTER_BITS),
        })

    def elaborate(self, platform):
        m = Module()
        regs, now = self.regs, self.now
        use_prng = regs.source == Source.PRNG
        take_idle = Signal()
        flush_until = Signal(TIME_BITS)
        flush_cycles = Signal(DURATION_BITS)
        m.d.comb += flush_cycles.eq(flush_rows(self._dmd) * regs.row_period)
        start_group = Signal(group_bits(self._dmd) + 1)

        restarted = Signal()                   # the controller is ready again after a restart

        def queue_first_planes():
            m.d.comb += [self.queue_first.valid.eq(1), self.queue_first.payload.eq(start_group)]
            m.d.sync += start_group.eq(start_group + 1)
            with m.If(start_group == self.n_groups - 1):
                m.next = "RUN"

        def restart_on_init():
            with m.If(~self.initialised):
                m.next = "RESTART"

        with m.FSM(name="start") as fsm:
            with m.State("WAIT"):
                with m.If(self.initialised & (self.offer.valid | use_prng)):
                    begin = self.start.payload
                    m.d.comb += [self.start.valid.eq(1), begin.take.eq(~use_prng),
                                 begin.slot.eq(Mux(use_prng, 0, self.offer.slot)),
                                 begin.depth.eq(Mux(use_prng, 1, self.offer.depth))]
                    with m.If(~use_prng):
                        m.d.comb += begin.showing.eq(self.offer.showing)
                    m.next = "QUEUE"
            with m.State("QUEUE"):
                queue_first_planes()
                restart_on_init()
            with m.State("RUN"):
                m.d.comb += self.running.eq(1)
                with m.If(take_idle):
                    m.next = "RELOAD"
                    with m.If(~self.all_ready):
                        m.next = "FLUSH"
                restart_on_init()
            with m.State("FLUSH"):
                # queued loads are dropped by the requester, looked-up ones by the bus, the words
                # asked for are discarded; then the first planes are queued, exactly
                # ``flush_cycles`` after the frame was taken
                m.d.comb += [self.running.eq(1), self.flushing.eq(1)]
                with m.If(self.drained & (diff(flush_until, now) <= 0)):
                    m.next = "RELOAD"
                restart_on_init()
            with m.State("RELOAD"):
                m.d.comb += self.running.eq(1)
                queue_first_planes()
                restart_on_init()
            with m.State("RESTART"):
                # no pulse, no load; what was under way is dropped as in FLUSH
                m.d.comb += self.flushing.eq(1)
                with m.If(self.initialised & self.drained):
                    m.d.comb += restarted.eq(1)
                    m.next = "RELOAD"

        # A newer streamed frame offered while no group plays replaces the preloaded first planes (the
        # next frame of a stored sequence waits for its turn); nothing
        # abandoned is pulsed (no trigger is obeyed before every group is loaded again), and the
        # settle times of the last pulses still hold. With ``reload`` at rest, the same frame is
        # loaded again under new registers.
        # (once a sequence played once has ended, the next frame offered is taken at once too)
        newer = ~use_prng & ~regs.chain & self.offer.valid & (~self.offer.sequence | self.ended)
        idle = fsm.ongoing("RUN") & ~self.playing
        resting = fsm.ongoing("RUN") & self.all_ready
        m.d.comb += [take_idle.eq((idle & newer & self._fits(m)) | (resting & self.reload)),
                     self.at_rest.eq(fsm.ongoing("WAIT") | resting)]
        with m.If(take_idle):
            wait = Mux(self.all_ready, 0, flush_cycles)
            m.d.comb += [self.retake.valid.eq(1), self.retake.payload.newer.eq(newer),
                         self.retake.payload.lead.eq(now + regs.reload_lead + wait)]
            m.d.sync += [start_group.eq(0), flush_until.eq(now + wait)]
        with m.If(restarted):
            # every group starts over: nothing it held is on the DMD any more
            m.d.comb += [self.retake.valid.eq(1), self.retake.payload.newer.eq(newer),
                         self.retake.payload.abandon.eq(1),
                         self.retake.payload.lead.eq(now + INIT_TO_DVALID)]
            m.d.sync += start_group.eq(0)

        # a trigger is obeyed when every group is ready; one that comes sooner is held (with
        # ``trigger_hold``) and obeyed on the first cycle they are, before any new one
        holding = Signal()
        ready = self.running & self.all_ready & ~take_idle
        release = holding & ready
        m.d.comb += self.ready.eq(ready & ~holding & ~self.ended)

        def obey():
            m.d.comb += [self.trigger.valid.eq(1), self.trigger.payload.eq((now + 2) & ~1)]
            m.d.sync += self.triggers.eq(self.triggers + 1)

        with m.If(release | fsm.ongoing("RESTART")):
            m.d.sync += holding.eq(0)
        with m.If(release):
            obey()
        with m.If(self.strobe):
            with m.If(~self.running):
                m.d.sync += self.early.eq(self.early + 1)
            with m.Elif(self.ended):
                m.d.sync += self.after_end.eq(self.after_end + 1)
            with m.Elif(ready & ~release):
                obey()
            with m.Elif(regs.trigger_hold & (~holding | release)):
                m.d.sync += [holding.eq(1), self.held.eq(self.held + 1)]
            with m.Else():
                m.d.sync += self.overruns.eq(self.overruns + 1)
        return m

    def _fits(self, m):
        """A newer frame may replace the waiting one now (:meth:`spec.schedule._Model.fits`):
        the triggers keep no steady pace, or the next one is overdue, or a reload ends first."""
        dmd, regs, now = self._dmd, self.regs, self.now
        # the periodic timer's pace is known from the start (its first strobe comes
        # ``period - 1`` cycles in), a pin's after two strobes (its ``last`` starts at -1 too,
        # unused until ``measured`` is set)
        last, measured = Signal(TIME_BITS, init=2**TIME_BITS - 1), Signal(TIME_BITS)
        seen = Signal()
        with m.If(self.strobe & self.running):
            m.d.sync += [last.eq(now), seen.eq(1)]
            with m.If(seen):
                m.d.sync += measured.eq(now - last)
        interval = Signal(TIME_BITS)
        m.d.comb += interval.eq(Mux(regs.trigger == TriggerMode.PERIODIC, regs.period, measured))
        R = row_cycles(dmd, self._beats)
        row_period = Signal(DURATION_BITS)
        bound = Signal(TIME_BITS)
        m.d.comb += [
            row_period.eq(Mux(regs.row_period > R, regs.row_period, R)),
            bound.eq(reload_cycles(dmd, self._beats, row_period, regs.reload_lead)),
        ]
        due = last + interval
        fits = Signal()
        m.d.comb += fits.eq((interval == 0) | (diff(now, due + (interval >> 3)) > 0) | (diff(due, now + bound) > 0))
        return fits
