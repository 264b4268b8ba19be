"""RST_ACTIVE after each clocking pulse: the settle time counted from its fall, and its faults.

The planner times a group's settle from its own pulse (``t_rst + t_settle``, TI's figures). The
DLPC410 says when the reset really ended: RST_ACTIVE falls. A group's memory may change only
once its pulse has been followed by RST_ACTIVE rising and falling, and ``t_settle`` has passed
since the fall, whichever is later than the planner's time; so a controller that holds
RST_ACTIVE longer than the facts table says delays the loads instead of breaking the settle
rule. A fall later than planned is counted. So are RST_ACTIVE never rising after a pulse (the
group is released ``t_rst + t_settle`` after the planned fall) and RST_ACTIVE stuck high as long
past it (the group waits for the fall; no pulse is made while it is high). RST_ACTIVE seen in
the synchroniser's cycles after a pulse was high before the pulse reached the pins (:data:`BLIND`):
it is not this pulse's (a high that lasts is seen again later), so a short high just before a
pulse cannot pass for the pulse's own reset and end its wait early. With the loose reading
(``strict_rst`` low) another group may pulse while RST_ACTIVE is high; the one pin then no
longer tells when the earlier group's reset ended, and that group falls back on the planned time.

The longest RST_ACTIVE seen with the strict reading (from a pulse's decision to the fall, dated
as above) is reported, so that the host can plan with the controller's own time instead of the
facts table's (:func:`spec.schedule.plan` adds the synchroniser's :data:`FALL_LATENCY`: the strict
reading's pin check sees the fall that much later).

Every time is a countdown (:mod:`gateware.countdown`) and the fault time is a chain of them
(``t_rst`` to the planned fall, ``t_rst + t_settle`` more), so no sum is formed.
"""

from amaranth import Cat, Module, Signal
from amaranth.lib import enum, wiring
from amaranth.lib.wiring import In, Out

from spec.schedule import DECISION_TO_PINS, FALL_LATENCY

from ..countdown import Countdown
from ..counter import Counter
from ..registers import Registers
from .layouts import COUNTER_BITS

__all__ = ["ResetWatch", "BLIND"]

#: Cycles after a pulse is applied (a cycle after its decision) in which ``rst_active`` still
#: shows the pin from before the pulse reached it.
BLIND = DECISION_TO_PINS - 1 + FALL_LATENCY


class Phase(enum.Enum, shape=2):
    IDLE = 0     # nothing pending: the memory may change on the planner's time
    RISE = 1     # pulsed: RST_ACTIVE has not risen yet
    FALL = 2     # RST_ACTIVE high: waiting for it to fall
    STUCK = 3    # RST_ACTIVE high far longer than planned (counted once): still waiting


class ResetWatch(wiring.Component):
    """Watch RST_ACTIVE for every pulse group.

    Parameters
    ----------
    dmd : :class:`spec.facts.DmdType`

    Members
    -------
    regs : In(:class:`~gateware.registers.Registers`)
        ``t_rst``, ``t_settle``, ``strict_rst``.
    rst_active : In(1)
        RST_ACTIVE, synchronised (:data:`FALL_LATENCY` cycles behind the pin).
    pulse : In(blocks); pulse_any : In(1)
        Bit g: group g's pulse, decided last cycle, is applied now; some bit of ``pulse``
        (registered apart, for the depth of what it decides).
    free : Out(blocks)
        Bit g: by the next cycle, group g's last pulse has been followed by RST_ACTIVE's fall and
        ``t_settle`` since (or nothing is pending): its memory may change as far as the pin goes.
    late : Out(COUNTER_BITS)
        Falls later than ``t_rst`` after the last pulse.
    faults : Out(COUNTER_BITS)
        RST_ACTIVE did not rise after a pulse, or stayed high, ``t_rst + t_settle`` past its
        planned fall.
    longest : Out(COUNTER_BITS)
        The longest RST_ACTIVE seen (strict reading), in cycles from the pulse's decision to the
        fall. It catches up with each new longest by one every other cycle, so that it crosses
        clock domains as a counter does.
    """

    def __init__(self, dmd):
        self._dmd = dmd
        groups = dmd.blocks
        super().__init__({
            "regs": In(Registers),
            "rst_active": In(1),
            "pulse": In(groups),
            "pulse_any": In(1),
            "free": Out(groups),
            "late": Out(COUNTER_BITS),
            "faults": Out(COUNTER_BITS),
            "longest": Out(COUNTER_BITS),
        })

    def elaborate(self, platform):
        m = Module()
        regs, blocks = self.regs, self._dmd.blocks
        pulsed = self.pulse_any

        # the planned fall (t_rst after the pulse's decision), and t_rst + t_settle past it
        m.submodules.planned = planned = Countdown(16, lag=1, flags="settled")
        m.submodules.past_rst = past_rst = Countdown(16, lag=1, flags="settled")
        m.submodules.past_settle = past_settle = Countdown(16, lag=1, flags="settled")
        stage = Signal(range(3), init=2)
        # (each step on the end of the one before for this pulse: a later pulse starts over)
        m.d.comb += [planned.load.eq(pulsed), planned.value.eq(regs.t_rst),
                     past_rst.load.eq(planned.ends & (stage == 0)), past_rst.value.eq(regs.t_rst),
                     past_settle.load.eq(past_rst.ends & (stage == 1)), past_settle.value.eq(regs.t_settle)]
        with m.If(pulsed):
            m.d.sync += stage.eq(0)
        with m.Elif(past_rst.load):
            m.d.sync += stage.eq(1)
        with m.Elif(past_settle.load):
            m.d.sync += stage.eq(2)
        overdue = (stage == 2) & past_settle.done

        phase = [Signal(Phase, name=f"phase{g}") for g in range(blocks)]
        # cycles after a group's pulse in which RST_ACTIVE still shows the pins before it
        blind = [Signal(range(BLIND + 1), name=f"blind{g}") for g in range(blocks)]
        high = self.rst_active
        missing, stuck = Signal(blocks), Signal(blocks)
        for g in range(blocks):
            waits = (phase[g] == Phase.FALL) | (phase[g] == Phase.STUCK)
            falls = waits & ~high
            # the settle time from the fall, dated FALL_LATENCY cycles before it is seen
            m.submodules[f"settled{g}"] = settled = Countdown(16, lag=FALL_LATENCY, within=(2,), flags="settled")
            m.d.comb += [settled.load.eq(falls), settled.value.eq(regs.t_settle)]
            idle_next = Signal(name=f"idle_next{g}")
            with m.If(blind[g] != 0):
                m.d.sync += blind[g].eq(blind[g] - 1)
            with m.If(self.pulse[g]):
                m.d.sync += [phase[g].eq(Phase.RISE), blind[g].eq(BLIND)]
            with m.Elif(pulsed & ~regs.strict_rst):
                m.d.sync += phase[g].eq(Phase.IDLE)
                m.d.comb += idle_next.eq(1)
            with m.Else():
                with m.Switch(phase[g]):
                    with m.Case(Phase.IDLE):
                        m.d.comb += idle_next.eq(1)
                    with m.Case(Phase.RISE):
                        with m.If(high & (blind[g] == 0)):
                            m.d.sync += phase[g].eq(Phase.FALL)
                        with m.Elif(overdue):
                            m.d.comb += [missing[g].eq(1), idle_next.eq(1)]
                            m.d.sync += phase[g].eq(Phase.IDLE)
                    with m.Case(Phase.FALL, Phase.STUCK):
                        with m.If(~high):
                            m.d.comb += idle_next.eq(1)
                            m.d.sync += phase[g].eq(Phase.IDLE)
                        with m.Elif((phase[g] == Phase.FALL) & overdue):
                            m.d.comb += stuck[g].eq(1)
                            m.d.sync += phase[g].eq(Phase.STUCK)
            # (a fall this cycle loads the settle countdown: its flags are the next cycle's)
            m.d.comb += self.free[g].eq(idle_next & settled.within[0] & ~falls)

        # the counters take registered events: one cycle late, as every status count may be
        falls_any = ~high & Cat((p == Phase.FALL) | (p == Phase.STUCK) for p in phase).any()
        fell, faulty, fault = Signal(), Signal(blocks), Signal()
        m.d.sync += [fell.eq(falls_any), faulty.eq(missing | stuck), fault.eq(faulty.any())]
        # the fall is late when, at the cycle it is dated (FALL_LATENCY before it was seen), the
        # planned fall had passed: the flag of then, a cycle more for the registered event
        late_then = Signal(FALL_LATENCY + 1)
        m.d.sync += late_then.eq(Cat(planned.late, late_then[:-1]))
        m.submodules.late_count = late_count = Counter(COUNTER_BITS)
        m.submodules.fault_count = fault_count = Counter(COUNTER_BITS)
        m.d.comb += [late_count.inc.eq(fell & late_then[-1]), self.late.eq(late_count.count),
                     fault_count.inc.eq(fault), self.faults.eq(fault_count.count)]

        # the longest reset: cycles from the pulse's decision to the fall as dated; with the
        # loose reading another group's pulse may come first, and the fall no longer dates it
        # (restarted as the pulse is applied, a cycle after its decision: on the cycle the fall
        # is seen, FALL_LATENCY cycles after it, the count is the length)
        m.submodules.elapsed = elapsed = Counter(COUNTER_BITS)
        m.d.comb += [elapsed.restart.eq(pulsed), elapsed.inc.eq(1)]
        length, longest = Signal(COUNTER_BITS), Signal(COUNTER_BITS)
        measured = Signal(2)                   # a new length: taken, compared
        m.d.sync += measured.eq(Cat(regs.strict_rst & falls_any, measured[0]))
        with m.If(regs.strict_rst & falls_any):
            m.d.sync += length.eq(elapsed.count)
        # length > longest, a limb at a time: each limb's order, then the whole
        half = COUNTER_BITS // 2
        above, same = Signal(2), Signal(2)
        m.d.sync += [above.eq(Cat(length[:half] > longest[:half], length[half:] > longest[half:])),
                     same.eq(length[half:] == longest[half:])]
        with m.If(measured[1] & (above[1] | same & above[0])):
            m.d.sync += longest.eq(length)
        # shown catches up one every other cycle (each step compared anew)
        m.submodules.shown = shown = Counter(COUNTER_BITS)
        behind, stepped = Signal(), Signal()
        m.d.sync += [behind.eq(shown.count != longest), stepped.eq(shown.inc)]
        m.d.comb += [shown.inc.eq(behind & ~stepped), self.longest.eq(shown.count)]
        return m
