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
when every group is loaded and waits (in ``GROUPS``, once frames follow triggers, group 0 loaded
and the others waiting, their first loads under way); otherwise it is an overrun (or early, before
the groups run).

A controller that initialises again (``initialised`` falls: INIT_ACTIVE high again, or
ECP2_FINISHED low; or the store lost its memory) has lost the DMD's memory: ``RESTART`` stops
every pulse and load, drops the loads under way as ``FLUSH`` does, and once the controller is
ready again every group starts over from its first plane (of the newest frame) as after a
reload, no sooner than ``init_to_dvalid`` clocks later; the groups then wait for a trigger.

Each decision (a start, a frame taken, a restart, a trigger obeyed, held or refused) is made
from the state the decisions so far leave (the planner's, and this part's own decision of the
cycle before, counted in) and registered; it is applied the cycle after (so a trigger's first
pulse falls due two cycles after its strobe). The trigger's pace reaches the newer-frame guard
:data:`spec.schedule.PACE_LAG` cycles after the trigger.
"""

from amaranth import Cat, Const, Module, Mux, Signal
from amaranth.lib import data, wiring
from amaranth.lib.wiring import In, Out

from spec.schedule import INIT_TO_DVALID, PACE_LAG, flush_rows, reload_cycles, row_cycles

from ..countdown import Countdown
from ..counter import Counter
from ..limbs import pipelined_sum
from ..registers import DURATION_BITS, Registers, Source, TriggerMode
from .frame_offer import Offer
from .layouts import COUNTER_BITS, event, group_bits
from .planner import START

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
    n_groups : In(range(blocks + 1))
    all_ready : In(1)
        The planner's groups are all loaded and wait (as its state is).
    trigger_ready : In(1)
        The planner's groups may take a trigger (as its state is): ``all_ready``, or in
        ``GROUPS`` group 0 loaded and every group waiting (used once a trigger was obeyed since
        the last start, take or restart).
    counting : In(1)
        The time base counts (the controller is initialised): the first loads wait
        ``init_to_dvalid`` clocks from its first cycle.
    initialised : In(1)
        The DLPC410 is initialised and the store holds its frames (it may fall again: the
        controller restarts, or the DDR2 loses its calibration).
    strobe : In(1)
        A trigger (from :class:`~gateware.dlpc410.trigger.Trigger`).
    reload : In(1)
        New registers this cycle (only while ``at_rest``): load every group's first plane again.
    at_rest : Out(1)
        No frame plays and no load is under way: before the first frame, or every group loaded
        and waiting for a trigger (as registered the cycle before, less this cycle's decisions).
    offer : In(:class:`~gateware.dlpc410.frame_offer.Offer`)
        The frame the store offers (``valid`` unless a group's take answers it now; a start or
        retake applied now is counted in here).
    playing, ended : In(1)
        From the planner.
    drained : In(1)
        No load job queued or looked up, and no word owed by the store.
    start, retake, trigger, queue_first : Out(event)
        The planner's commands (see :class:`~gateware.dlpc410.planner.Planner`), applied now.
    lead_over : Out(1)
        The memory may change by the next cycle as far as a retake's lead (and the flush before
        it) and the first loads' wait after initialisation go (not in the cycle a retake is
        applied: see ``retake``).
    running : Out(1)
        The groups run (pulses and loads may be made).
    ready : Out(1)
        A trigger now would have been obeyed at once on the cycle before (registered): a frame is
        loaded in every group, none plays, no newer frame is being taken and no trigger is held
        (a sync master's ready line).
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
        group_index_bits = group_bits(dmd)
        blocks = dmd.blocks
        super().__init__({
            "regs": In(Registers),
            "n_groups": In(range(blocks + 1)),
            "all_ready": In(1),
            "trigger_ready": In(1),
            "counting": In(1),
            "initialised": In(1),
            "strobe": In(1),
            "reload": In(1),
            "at_rest": Out(1),
            "offer": In(Offer),
            "playing": In(1),
            "ended": In(1),
            "drained": In(1),
            "start": Out(event(START)),
            "retake": Out(event(data.StructLayout({"newer": 1, "abandon": 1}))),
            "trigger": Out(1),
            "queue_first": Out(event(group_index_bits)),
            "lead_over": Out(1),
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
        regs = self.regs
        use_prng = regs.source == Source.PRNG
        start_group = Signal(group_bits(self._dmd) + 1)

        # the decisions of the cycle before, applied now
        did = Signal(data.StructLayout({
            "start": 1, "take": 1, "newer": 1, "flush": 1, "restart": 1,
            "obey": 1, "hold": 1, "release": 1, "overrun": 1, "early": 1, "after_end": 1}))
        begun = Signal(START)                  # the frame a start begins

        # ---- the state the decisions so far leave ----
        retakes = Signal()                     # a frame taken or a restart (registered apart)
        settles = did.obey | did.start | retakes
        all_ready = self.all_ready & ~settles
        trigger_ready = self.trigger_ready & ~settles
        playing = self.playing | did.obey
        ended = self.ended & ~did.start & ~(did.take & did.newer)
        holding = Signal()
        holding_now = (holding | did.hold) & ~did.release

        # ---- the states, their flags registered with them ----
        flush_over = self._lead(m, did)
        run, waiting, restarting = self._states(m, did, start_group, flush_over)

        # ---- decisions ----
        # a newer streamed frame offered while no group plays replaces the preloaded first planes
        # (the next frame of a stored sequence waits for its turn; once a sequence played once has
        # ended, the next frame offered is taken at once too); nothing abandoned is pulsed (no
        # trigger is obeyed before every group is loaded again), and the settle times of the last
        # pulses still hold. With ``reload`` at rest, the same frame is loaded again under new
        # registers.
        # (the offer is ``valid`` unless a group's take answers it now; a start, restart or newer
        # frame's take applied now answers it too, and ends a sequence's ``ended``: neither is
        # counted in here, off the loop from the decisions applied to the next, as no frame is
        # taken or trigger obeyed then: a start or restart leaves ``run`` low, every take leaves
        # ``all_ready`` low, and a newer frame's take is masked below)
        newer = ~use_prng & ~regs.chain & self.offer.valid & (~self.offer.sequence | self.ended)
        fits = self._fits(m)
        takes = run & ~(did.take & did.newer) & ((~playing & newer & fits) | (all_ready & self.reload))
        starts = waiting & self.initialised & (self.offer.valid | use_prng) & ~did.start
        # a trigger is obeyed when every group is ready; one that comes sooner is held (with
        # ``trigger_hold``) and obeyed on the first cycle they are, before any new one (every
        # group ready, none plays: only a newer frame or a reload could be taken instead)
        # (in GROUPS the planner's ``trigger_ready`` spares groups whose first loads are under
        # way, queued each at its own last dark pulse; after a start, take or restart every
        # first plane was queued at once, and the trigger waits for them all)
        reloaded = Signal(init=1)
        with m.If(did.start | retakes):
            m.d.sync += reloaded.eq(1)
        with m.If(did.obey):
            m.d.sync += reloaded.eq(0)
        ready = self.running & Mux(reloaded, all_ready, trigger_ready) & ~(run & ((newer & fits) | self.reload))
        release = holding_now & ready
        holds = regs.trigger_hold & (~holding_now | release)
        m.d.sync += [
            did.start.eq(starts), did.take.eq(takes), did.newer.eq(newer), did.flush.eq(~all_ready),
            did.restart.eq(restarting), did.release.eq(release),
            did.obey.eq(ready & (holding_now | (self.strobe & ~ended))),
            retakes.eq(takes | restarting),
            did.early.eq(self.strobe & ~self.running),
            did.after_end.eq(self.strobe & self.running & ended),
            did.hold.eq(self.strobe & self.running & ~ended & ~(ready & ~holding_now) & holds),
            did.overrun.eq(self.strobe & self.running & ~ended & ~(ready & ~holding_now) & ~holds),
            begun.slot.eq(Mux(use_prng, 0, self.offer.slot)), begun.depth.eq(Mux(use_prng, 1, self.offer.depth)),
            begun.low_plane.eq(Mux(use_prng, 7, self.offer.low_plane)),
            begun.showing.eq(Mux(use_prng, 0, self.offer.showing.as_value())), begun.take.eq(~use_prng),
        ]

        # ---- applied ----
        m.d.comb += [self.start.valid.eq(did.start), self.start.payload.eq(begun),
                     self.retake.valid.eq(retakes),
                     self.retake.payload.newer.eq(did.newer), self.retake.payload.abandon.eq(did.restart),
                     self.trigger.eq(did.obey)]
        with m.If(did.start | retakes):
            m.d.sync += start_group.eq(0)
        with m.If(did.release | (self.flushing & ~self.running)):      # (RESTART)
            m.d.sync += holding.eq(0)
        with m.If(did.hold):
            m.d.sync += holding.eq(1)
        for name, happened in (("triggers", did.obey), ("overruns", did.overrun), ("early", did.early),
                               ("held", did.hold), ("after_end", did.after_end)):
            m.submodules[name] = counter = Counter(COUNTER_BITS)
            m.d.comb += [counter.inc.eq(happened), getattr(self, name).eq(counter.count)]

        # ---- what the crossing and the sync master read (registered, less this cycle's
        # decisions applied now) ----
        rest = Signal(init=1)                  # (it starts in WAIT)
        m.d.sync += [rest.eq((waiting & ~did.start) | (run & all_ready)),
                     self.ready.eq(ready & ~holding_now & ~ended)]
        m.d.comb += self.at_rest.eq(rest & ~settles)
        return m

    def _states(self, m, did, start_group, flush_over):
        """The states (see the module's notes), from the decisions applied now (``did``), with
        ``start_group`` the group whose first plane is queued next and ``flush_over`` the flush's
        end: returns the flags ``run`` (RUN) and ``waiting`` (WAIT), registered with the state,
        and ``restarting`` (RESTART, and the controller is ready again)."""
        restarting = Signal()                  # RESTART: the controller is ready again
        last_group = Signal.like(self.n_groups)          # (the registers hold still)
        m.d.sync += last_group.eq(self.n_groups - 1)
        # the state's flags, registered with it (set on each change of state)
        run = Signal()
        queueing = Signal()                    # QUEUE or RELOAD: a first plane queued each cycle
        waiting = Signal(init=1)               # WAIT

        def goto(state):
            m.next = state
            m.d.sync += [self.running.eq(state in ("RUN", "FLUSH", "RELOAD")), run.eq(state == "RUN"),
                         self.flushing.eq(state in ("FLUSH", "RESTART")),
                         queueing.eq(state in ("QUEUE", "RELOAD")), waiting.eq(state == "WAIT")]

        def restart_on_init():
            with m.If(~self.initialised):
                goto("RESTART")

        with m.FSM(name="start"):
            with m.State("WAIT"):
                with m.If(did.start):
                    goto("QUEUE")
            with m.State("QUEUE"):
                self._queue_first_planes(m, start_group, goto, last_group)
                restart_on_init()
            with m.State("RUN"):
                with m.If(did.take):
                    goto("RELOAD")
                    with m.If(did.flush):
                        goto("FLUSH")
                restart_on_init()
            with m.State("FLUSH"):
                # queued loads are dropped by the requester, looked-up ones by the bus, the words
                # asked for are discarded; then the first planes are queued, exactly
                # ``flush_rows * row_period`` cycles after the frame was taken
                with m.If(self.drained & flush_over):
                    goto("RELOAD")
                restart_on_init()
            with m.State("RELOAD"):
                self._queue_first_planes(m, start_group, goto, last_group)
                restart_on_init()
            with m.State("RESTART"):
                # no pulse, no load; what was under way is dropped as in FLUSH
                m.d.comb += restarting.eq(self.initialised & self.drained & ~did.restart)
                with m.If(did.restart):
                    goto("RELOAD")
        # (from the state's flag, not its decode)
        m.d.comb += [self.queue_first.valid.eq(queueing), self.queue_first.payload.eq(start_group)]
        return run, waiting, restarting

    def _queue_first_planes(self, m, start_group, goto, last_group):
        m.d.sync += start_group.eq(start_group + 1)
        with m.If(start_group == last_group):
            goto("RUN")

    def _lead(self, m, did):
        """The flush (``flush_rows`` row periods from a frame taken with loads under way) and the
        lead (``reload_lead`` after a frame taken, after the flush; ``init_to_dvalid`` after the
        time base starts or the controller is ready again), as chained countdowns: drives
        ``lead_over`` and returns whether the flush time is over."""
        regs, rows = self.regs, flush_rows(self._dmd)
        m.submodules.flush_time = flush_time = Countdown(8, lag=1, flags="settled")
        m.submodules.lead_time = lead_time = Countdown(16, lag=1, within=(2,), flags="given")
        lead_flags = Signal(lead_time.flags_layout())
        m.d.sync += lead_flags.eq(lead_time.flags_of(regs.reload_lead))

        def lead(value, flags):
            m.d.comb += [lead_time.load.eq(1), lead_time.value.eq(value), lead_time.load_flags.eq(flags)]

        left = Signal(range(rows))             # row periods still to count after this one
        last = Signal()                        # ``left`` is 0
        flushing = Signal()
        m.d.comb += flush_time.value.eq(regs.row_period)
        with m.If(did.take & did.flush):
            m.d.comb += flush_time.load.eq(1)
            m.d.sync += [left.eq(rows - 1), last.eq(rows == 1), flushing.eq(1)]
        with m.Elif(flushing & flush_time.ends):
            with m.If(~last):
                m.d.comb += flush_time.load.eq(1)
                m.d.sync += [left.eq(left - 1), last.eq(left == 1)]
            with m.Else():
                lead(regs.reload_lead, lead_flags)
                m.d.sync += flushing.eq(0)
        with m.If(~self.counting):
            # the time base's cycle 0 is the first it counts: its first loads from init_to_dvalid
            lead(INIT_TO_DVALID + 2, lead_time.flags_of(INIT_TO_DVALID + 2))
        with m.Elif(did.take & ~did.flush):
            lead(regs.reload_lead, lead_flags)
        with m.Elif(did.restart):
            lead(INIT_TO_DVALID, lead_time.flags_of(INIT_TO_DVALID))
        # (a countdown loaded this cycle has its last count's flags: the planner changes no
        # memory in the cycle a frame is taken, when the lead is loaded, and the flush's end
        # loads it while ``flushing`` still holds)
        m.d.comb += self.lead_over.eq(~flushing & lead_time.within[0])
        return ~flushing | (last & flush_time.done)

    def _fits(self, m):
        """A newer frame may replace the waiting one (:meth:`spec.schedule._Model.fits`): the
        triggers keep no steady pace, or the next one is overdue by an eighth of the interval, or
        a reload ends before it. At each trigger counted (and, before the time base starts, as
        if the periodic timer's strobe came on each cycle) the interval (the periodic timer's,
        or the time since the trigger before) enters a pipeline that forms its two limits in
        16-bit limbs; countdowns loaded at its end (their lag the pipeline's) answer them, from
        :data:`~spec.schedule.PACE_LAG` cycles after the trigger."""
        dmd, regs = self._dmd, self.regs
        cycles_per_row = row_cycles(dmd, self._beats)
        periodic = regs.trigger == TriggerMode.PERIODIC

        # the reload bound (spec.schedule.reload_cycles), from the registers: a product and two
        # sums, each registered (the registers hold still); no carry chain over 16 bits: the
        # product from the rows' low and high bytes, the sums in limbs
        rows = flush_rows(dmd) + dmd.rows
        row_period, by_low, by_high, product = Signal(8), Signal(16), Signal(12), Signal(21)
        m.d.sync += [row_period.eq(Mux(regs.row_period > cycles_per_row, regs.row_period, cycles_per_row)),
                     by_low.eq(row_period * (rows & 0xFF)), by_high.eq(row_period * (rows >> 8)),
                     product.eq(Cat(by_low[:8], by_low[8:] + by_high))]
        lead, _ = pipelined_sum(m, [regs.reload_lead] * 2, lambda k: Const(reload_cycles(dmd, self._beats, 0, 0), 16),
                                0, "lead")
        bound, _ = pipelined_sum(m, [product] * 2, lambda k: Cat(lead, Const(0, 4)), 0, "bound")

        # the interval of each trigger counted
        m.submodules.since = since = Counter(DURATION_BITS, restart_value=1)
        # (registered first, a cycle after the strobe: its source's choice is off the counter's
        # restart; the interval between two is the same)
        counted = Signal()
        m.d.sync += counted.eq(self.strobe & self.running)
        seen = Signal()
        with m.If(counted):
            m.d.sync += seen.eq(1)
        m.d.comb += [since.inc.eq(1), since.restart.eq(counted)]
        stages = 4                             # the interval, then its three limbs
        go = Signal(stages + 1)
        interval = [Signal(DURATION_BITS, name=f"interval{k}") for k in range(stages - 1)]
        m.d.sync += [go.eq(Cat(counted | ~self.counting, go[:-1])),
                     interval[0].eq(Mux(periodic, regs.period, Mux(seen, since.count, 0)))]
        for k in range(1, stages - 1):
            m.d.sync += interval[k].eq(interval[k - 1])
        # interval + interval / 8, and interval - bound (0 below it), a limb a stage
        late_at, _ = pipelined_sum(m, interval, lambda k: Cat(interval[k][3:], Const(0, 3)), 0, "late_at")
        early_at, reaches = pipelined_sum(m, interval, lambda k: ~Cat(bound, Const(0, DURATION_BITS - len(bound))),
                                          1, "early_at")
        zero = Signal(stages - 1)
        m.d.sync += zero.eq(Cat(interval[0] == 0, zero[:-1]))

        # the limits and their countdowns' flags, registered; loaded a stage later
        assert stages + 3 == PACE_LAG            # counted a cycle late; the flags follow their load
        m.submodules.overdue = overdue = Countdown(DURATION_BITS + 1, lag=stages + 1, flags="given")
        m.submodules.too_soon = too_soon = Countdown(DURATION_BITS, lag=stages + 1, flags="given")
        early = Mux(reaches, early_at[:DURATION_BITS], 0)
        limits = Signal(data.StructLayout({"late": DURATION_BITS + 1, "late_flags": overdue.flags_layout(),
                                           "early": DURATION_BITS, "early_flags": too_soon.flags_layout(),
                                           "steady": 1}))
        m.d.sync += [limits.late.eq(late_at), limits.late_flags.eq(overdue.flags_of(late_at)),
                     limits.early.eq(early), limits.early_flags.eq(too_soon.flags_of(early)),
                     limits.steady.eq(~zero[-1])]
        steady = Signal()
        with m.If(go[-1]):
            m.d.comb += [overdue.load.eq(1), overdue.value.eq(limits.late), overdue.load_flags.eq(limits.late_flags),
                         too_soon.load.eq(1), too_soon.value.eq(limits.early),
                         too_soon.load_flags.eq(limits.early_flags)]
            m.d.sync += steady.eq(limits.steady)
        return ~steady | overdue.late | ~too_soon.done
