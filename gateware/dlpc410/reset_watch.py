"""RST_ACTIVE after each clocking pulse: the settle time counted from its fall, and its faults.

The planner times a group's settle from its own pulse (``t_rst + t_settle``, TI's figures). The
DLPC410 says when the reset really ended: RST_ACTIVE falls. A group's memory may change only
once its pulse has been followed by RST_ACTIVE rising and falling, and ``t_settle`` has passed
since the fall, whichever is later than the planner's time; so a controller that holds
RST_ACTIVE longer than the facts table says delays the loads instead of breaking the settle
rule. A fall later than planned is counted. So are RST_ACTIVE never rising after a pulse (the
group is released ``t_rst + t_settle`` after the planned fall) and RST_ACTIVE stuck high as long
past it (the group waits for the fall; no pulse is made while it is high). RST_ACTIVE seen in
the synchroniser's cycles after a pulse was high before the pulse reached the pins: it is not
this pulse's (a high that lasts is seen again two cycles later), so a short high just before a
pulse cannot pass for the pulse's own reset and end its wait early. With the loose reading
(``strict_rst`` low) another group may pulse while RST_ACTIVE is high; the one pin then no
longer tells when the earlier group's reset ended, and that group falls back on the planned time.

The longest RST_ACTIVE seen with the strict reading (from a pulse's decision to the fall, dated
as above) is the ``t_rst`` a plan for this controller needs: it is reported, so that the host can
plan with the controller's own time instead of the facts table's.
"""

from amaranth import Array, Cat, Module, Signal
from amaranth.lib import data, enum, wiring
from amaranth.lib.wiring import In, Out

from ..registers import TIME_BITS, Registers
from .layouts import COUNTER_BITS, event, group_bits
from .timebase import diff

__all__ = ["ResetWatch", "FALL_LATENCY"]

#: Cycles from RST_ACTIVE falling at the pin to its fall at ``rst_active`` (the two-flip-flop
#: synchroniser at least): the fall is dated this much earlier, never later than it was.
FALL_LATENCY = 2


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
        ``t_rst``, ``t_settle``.
    now : In(TIME_BITS)
    rst_active : In(1)
        RST_ACTIVE, synchronised (:data:`FALL_LATENCY` cycles behind the pin).
    pulse : In(event(group))
        The bus made this group's clocking pulse this cycle.
    waiting : Out(blocks)
        Bit g: group g's last pulse has not yet been followed by RST_ACTIVE's fall; its memory
        must not change.
    fell : Out(event(groups, settled))
        RST_ACTIVE fell: the groups of ``groups`` may change their memory from ``settled`` on
        (the fall and ``t_settle``).
    late : Out(COUNTER_BITS)
        Falls later than ``t_rst`` after the last pulse.
    faults : Out(COUNTER_BITS)
        RST_ACTIVE did not rise after a pulse, or stayed high, ``t_rst + t_settle`` past its
        planned fall.
    longest : Out(COUNTER_BITS)
        The longest RST_ACTIVE seen (strict reading), in cycles from the pulse's decision to the
        fall. It catches up with each new longest by one a cycle, so that it crosses clock
        domains as a counter does.
    """

    def __init__(self, dmd):
        self._dmd = dmd
        groups = dmd.blocks
        super().__init__({
            "regs": In(Registers),
            "now": In(TIME_BITS),
            "rst_active": In(1),
            "pulse": In(event(group_bits(dmd))),
            "waiting": Out(groups),
            "fell": Out(event(data.StructLayout({"groups": groups, "settled": TIME_BITS}))),
            "late": Out(COUNTER_BITS),
            "faults": Out(COUNTER_BITS),
            "longest": Out(COUNTER_BITS),
        })

    def elaborate(self, platform):
        m = Module()
        regs, now, G = self.regs, self.now, self._dmd.blocks
        phase = Array(Signal(Phase, name=f"phase{g}") for g in range(G))
        # cycles after a group's pulse in which RST_ACTIVE still shows the pins before it
        blind = Array(Signal(range(FALL_LATENCY + 1), name=f"blind{g}") for g in range(G))
        # RST_ACTIVE is one pin for every group: the fall the last pulse plans
        planned_fall = Signal(TIME_BITS)
        fell_at = Signal(TIME_BITS)
        m.d.comb += fell_at.eq(now - FALL_LATENCY)
        # a fault: still no rise, or no fall, ``t_rst + t_settle`` after the planned fall
        overdue = diff(planned_fall + regs.t_rst + regs.t_settle, now) <= 0
        falls = Signal()
        m.d.comb += falls.eq(~self.rst_active & Cat(
            (phase[g] == Phase.FALL) | (phase[g] == Phase.STUCK) for g in range(G)).any())

        missing, stuck = Signal(), Signal()
        for g in range(G):
            with m.If(blind[g] != 0):
                m.d.sync += blind[g].eq(blind[g] - 1)
            with m.Switch(phase[g]):
                with m.Case(Phase.RISE):
                    with m.If(self.rst_active & (blind[g] == 0)):
                        m.d.sync += phase[g].eq(Phase.FALL)
                    with m.Elif(overdue):
                        m.d.comb += missing.eq(1)
                        m.d.sync += phase[g].eq(Phase.IDLE)
                with m.Case(Phase.FALL, Phase.STUCK):
                    with m.If(~self.rst_active):
                        m.d.sync += phase[g].eq(Phase.IDLE)
                    with m.Elif((phase[g] == Phase.FALL) & overdue):
                        m.d.comb += stuck.eq(1)
                        m.d.sync += phase[g].eq(Phase.STUCK)
            m.d.comb += [self.waiting[g].eq(phase[g] != Phase.IDLE),
                         self.fell.payload.groups[g].eq(falls & ((phase[g] == Phase.FALL)
                                                                 | (phase[g] == Phase.STUCK)))]
        with m.If(self.pulse.valid):
            with m.If(~regs.strict_rst):
                for g in range(G):
                    m.d.sync += phase[g].eq(Phase.IDLE)
            m.d.sync += [phase[self.pulse.payload].eq(Phase.RISE), blind[self.pulse.payload].eq(FALL_LATENCY),
                         planned_fall.eq(now + regs.t_rst)]

        m.d.comb += [self.fell.valid.eq(falls), self.fell.payload.settled.eq(fell_at + regs.t_settle)]
        with m.If(falls & (diff(fell_at, planned_fall) > 0)):
            m.d.sync += self.late.eq(self.late + 1)
        with m.If(missing | stuck):
            m.d.sync += self.faults.eq(self.faults + 1)

        # the longest reset: with the loose reading another group's pulse may come first, and
        # the fall no longer dates this pulse's reset
        longest = Signal(COUNTER_BITS)
        length = (fell_at - planned_fall + regs.t_rst)[:COUNTER_BITS]   # from the last pulse
        with m.If(falls & regs.strict_rst & (length > longest)):
            m.d.sync += longest.eq(length)
        with m.If(self.longest < longest):
            m.d.sync += self.longest.eq(self.longest + 1)
        return m
