"""Each pulse group's times, as countdowns (:mod:`gateware.countdown`): when its next pulse falls
due, when RST_ACTIVE allows its next pulse, and when its memory may change after its pulse.

Every time is loaded by an event of the cycle a decision is applied (one cycle after the bus
decided, so every countdown here has a lag of one: its time counts from the decision) and is
answered as registered flags, most of them for the next cycle, so that the planner registers the
bus's flags (:class:`~gateware.dlpc410.planner.Planner`) from them with little logic:

* a pulse: the group's next pulse ``delay`` on (the planner's per-group delay), RST_ACTIVE over
  ``t_rst`` on, and its memory free ``t_settle`` after that (the settle countdown starts when
  the RST_ACTIVE countdown ends, so no sum is formed: timers chain);
* a trigger obeyed: group 0's first pulse falls due two cycles after the trigger's cycle, and
  group ``g``'s ``stagger`` after group ``g - 1``'s (each loaded as the one before ends; with
  ``stagger`` 0 all at once). In :attr:`~spec.registers.PlaneOrder.GROUPS` each group's first
  pulse is its own offset after the trigger's two cycles instead, group 0's included (loaded
  as a timer of that time, ``start``, ends; offset 0: at once). A group waiting in that chain
  has no time yet: its flags say not due, and not soon (``stagger`` and each offset are 0 or at
  least a clear's row cycles and :data:`~spec.registers.MIN_CHAINED`, so no load that a first
  pulse could cut short can start meanwhile: :func:`spec.records.register_faults`; when a
  trigger comes while loads run, group 0's offset is at least
  :func:`spec.schedule.trigger_lead`, which covers the row under way too).
"""

from amaranth import Cat, Module, Mux, Signal
from amaranth.lib import data, wiring
from amaranth.lib.wiring import In, Out

from ..countdown import Countdown
from ..registers import DURATION_BITS, PlaneOrder, Registers

__all__ = ["GroupTimes"]

#: Every countdown here is loaded one cycle after the decision its time counts from.
LAG = 1


class GroupTimes(wiring.Component):
    """The groups' times (``sync``).

    Parameters
    ----------
    dmd : :class:`spec.facts.DmdType`
    soon, soon_clear : int
        Cycles a row and a clear (with its no-op rows) take on the bus: the ``soon`` flags.

    Members
    -------
    regs : In(:class:`~gateware.registers.Registers`)
        ``t_rst``, ``t_settle``, ``stagger``, ``strict_rst``, ``order`` and ``group_offsets``.
    pulse : In(blocks)
        Bit g: group g's pulse decided last cycle is applied now.
    pulse_any : In(1)
        Some bit of ``pulse`` (registered apart, for the flags' depth).
    delay : In(ArrayLayout(DURATION_BITS, blocks))
        Per group, the time from its pulse to its next one (set at least three cycles before the
        pulse that takes it is applied).
    obey : In(1)
        A trigger obeyed last cycle is applied now: the first pulses of the ``active`` groups.
    active : In(blocks)
    abandon : In(1)
        The groups leave their frame: a chain of first pulses stops.
    due : Out(blocks)
        Bit g: group g's pulse falls due by the next cycle.
    soon, soon_clear : Out(blocks)
        Bit g: an operation of ``soon`` (``soon_clear``) cycles decided next cycle would end after
        group g's pulse falls due.
    late : Out(blocks)
        Bit g: a pulse decided this cycle would be after the first even cycle of its time.
    rst_over : Out(blocks)
        Bit g: RST_ACTIVE no longer needs to be waited for by the next cycle, for a pulse of
        group g (strict: since any group's pulse; loose: since its own).
    settled : Out(blocks)
        Bit g: the group's memory may change by the next cycle, as far as its last pulse goes.
    frees_soon, frees_soon_clear : Out(blocks)
        Bit g: the group's RST_ACTIVE count is over and its memory may change before an
        operation of ``soon`` (``soon_clear``) cycles decided next cycle would end.
    at_once : Out(blocks)
        Bit g: a trigger obeyed times group g's first pulse at once (two cycles after the
        trigger's), not chained after the group before or offset (registered from ``active``,
        ``stagger`` and the offsets).
    """

    def __init__(self, dmd, *, soon, soon_clear):
        self._dmd, self._soon, self._soon_clear = dmd, soon, soon_clear
        groups = dmd.blocks
        super().__init__({
            "regs": In(Registers),
            "pulse": In(groups),
            "pulse_any": In(1),
            "delay": In(data.ArrayLayout(DURATION_BITS, groups)),
            "obey": In(1),
            "active": In(groups),
            "abandon": In(1),
            "due": Out(groups),
            "soon": Out(groups),
            "soon_clear": Out(groups),
            "late": Out(groups),
            "rst_over": Out(groups),
            "settled": Out(groups),
            "frees_soon": Out(groups),
            "frees_soon_clear": Out(groups),
            "at_once": Out(groups),
        })

    def elaborate(self, platform):
        m = Module()
        regs, blocks = self.regs, self._dmd.blocks
        # each group's first pulse after the time of those at once: ``g * stagger`` (chained) or
        # its offset (registered: the registers, and so ``active``, hold still long before a
        # trigger is obeyed)
        offsets, stagger_zero = Signal(), Signal()
        firsts = [Signal(24, name=f"first{g}") for g in range(blocks)]      # (group 0's: its offset)
        m.d.sync += [offsets.eq(regs.order == PlaneOrder.GROUPS), stagger_zero.eq(regs.stagger == 0)]
        m.d.sync += [first.eq(Mux(offsets, regs.group_offsets[g], regs.stagger)) for g, first in enumerate(firsts)]
        # the groups a trigger obeyed times at once, and those it chains
        at_once, chains = self.at_once, Signal(blocks)
        # (group 0 at once unless GROUPS offsets it: its offset is the least,
        # :func:`spec.records.register_faults`)
        unchained = Cat(Mux(offsets, first == 0, stagger_zero if g else 1) for g, first in enumerate(firsts))
        m.d.sync += [at_once.eq(self.active & unchained), chains.eq(self.active & ~unchained)]
        # the time of the pulses at once, for the offsets
        m.submodules.start = start = Countdown(3, lag=LAG)
        m.d.comb += [start.load.eq(self.obey), start.value.eq(2)]

        # the flags are for the next cycle: "by the next cycle" is within 2 cycles from now; the
        # values loaded hold still the cycle before (the registers), or their flags are worked
        # out ahead (each group's delay, as it is set)
        m.submodules.rst_any = rst_any = Countdown(16, lag=LAG, within=(2,), flags="settled")
        m.d.comb += [rst_any.load.eq(self.pulse_any), rst_any.value.eq(regs.t_rst)]
        chained = [Signal(name=f"chained{g}") for g in range(blocks)]
        pulse_cds = []
        for g in range(blocks):
            pulse_cd = Countdown(DURATION_BITS, lag=LAG, slack=1, within=(2, self._soon, self._soon_clear),
                                 flags="given")
            rst_cd = Countdown(16, lag=LAG, slack=1, within=(2,), flags="settled")
            settle_cd = Countdown(16, lag=LAG, within=(2, self._soon, self._soon_clear), flags="settled")
            m.submodules[f"pulse{g}"], m.submodules[f"rst{g}"], m.submodules[f"settle{g}"] = pulse_cd, rst_cd, settle_cd
            pulse_cds.append(pulse_cd)

            # the pulse time: the delay after a pulse; the first pulse of a frame (group 0's two
            # cycles after the trigger's, the others' ``stagger`` after the group's before them,
            # chained: as the group before ends its count, unless it waits itself and the end
            # is of its count before the trigger; or each its offset after ``start``'s time);
            # each source with its flags worked out ahead
            delay_flags = pulse_cd.flags_registered(m, self.delay[g], f"delay_flags{g}")
            first_flags = pulse_cd.flags_registered(m, firsts[g], f"first_flags{g}")
            first = self.obey & at_once[g]
            # (group 0 waits only for its offset: in the other orders it is never chained)
            after = (Mux(offsets, start.ends, pulse_cds[g - 1].ends & (~chained[g - 1] if g > 1 else 1))
                     if g else start.ends)
            chain = chained[g] & after
            m.d.sync += chained[g].eq(Mux(self.abandon | chain, 0, chained[g] | (self.obey & chains[g])))
            # (one of the three at most: a group pulses only loaded, never waiting for a trigger)
            m.d.comb += [
                pulse_cd.load.eq(self.pulse[g] | first | chain),
                pulse_cd.value.eq(Mux(self.pulse[g], self.delay[g], 0) | Mux(first, 2, 0)
                                  | Mux(chain, firsts[g], 0)),
                pulse_cd.load_flags.eq(Mux(self.pulse[g], delay_flags, 0) | Mux(first, pulse_cd.flags_of(2), 0)
                                       | Mux(chain, first_flags, 0)),
            ]

            # RST_ACTIVE over, then the settle time
            m.d.comb += [rst_cd.load.eq(self.pulse[g]), rst_cd.value.eq(regs.t_rst),
                         settle_cd.load.eq(rst_cd.ends), settle_cd.value.eq(regs.t_settle)]

            # (a countdown loaded this cycle has the flags of its last count: a group waiting in
            # the chain, or pulsing now, is masked; the strict RST_ACTIVE time of every group
            # restarts with any pulse)
            waiting = chained[g]
            m.d.comb += [
                self.due[g].eq(pulse_cd.within[0] & ~waiting),
                self.soon[g].eq(pulse_cd.within[1] & ~waiting),
                self.soon_clear[g].eq(pulse_cd.within[2] & ~waiting),
                self.late[g].eq(pulse_cd.late),
                self.rst_over[g].eq(Mux(regs.strict_rst, rst_any.within[0] & ~self.pulse_any,
                                        rst_cd.within[0] & ~self.pulse[g])),
                # the settle countdown is loaded once the RST_ACTIVE one has ended (its flags are
                # the settle time's from the cycle after)
                self.settled[g].eq(rst_cd.late & settle_cd.within[0] & ~self.pulse[g]),
                self.frees_soon[g].eq(rst_cd.late & settle_cd.within[1] & ~self.pulse[g]),
                self.frees_soon_clear[g].eq(rst_cd.late & settle_cd.within[2] & ~self.pulse[g]),
            ]
        return m
