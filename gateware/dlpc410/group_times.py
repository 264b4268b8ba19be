"""Each pulse group's times: when its next pulse falls due, when its memory may change again, and
when RST_ACTIVE allows its next pulse.

Times are kept as instants of the time base (:mod:`.timebase`) and answered as flags of this
cycle, so that the planner decides what a group does and this part only when: a pulse sets the
group's next pulse ``delay`` cycles on, its memory writable ``t_rst + t_settle`` on and its
RST_ACTIVE over ``t_rst`` on; a trigger sets every active group's first pulse, ``stagger`` apart;
a retake keeps every group's memory unchanged until at least ``lead``; RST_ACTIVE's fall keeps a
group's memory unchanged until its settle time is over (after a retake of the same cycle).
"""

from amaranth import Array, Module, Mux, Signal
from amaranth.lib import data, wiring
from amaranth.lib.wiring import In, Out

from spec.schedule import INIT_TO_DVALID

from ..registers import TIME_BITS, Registers
from .layouts import event, group_bits
from .timebase import diff

__all__ = ["GroupTimes"]


class GroupTimes(wiring.Component):
    """The groups' times (``sync``).

    Parameters
    ----------
    dmd : :class:`spec.facts.DmdType`
    soon, soon_clear : int
        Distances (cycles) for the ``soon`` and ``soon_clear`` flags.

    Members
    -------
    regs : In(:class:`~gateware.registers.Registers`)
    now : In(TIME_BITS)
        The time base.
    pulse : In(event(group, delay))
        The group pulses this cycle; its next pulse falls due ``delay`` cycles on.
    trigger : In(event(TIME_BITS))
        Group ``g`` (of those ``active``) pulses first at ``payload + g * stagger``.
    active : In(blocks)
        Bit g: group g is one of the reset mode's.
    retake : In(event(TIME_BITS))
        No group's memory changes before ``payload``.
    fell : In(event(groups, settled))
        RST_ACTIVE fell after the pulses of ``groups``: no change of their memory before
        ``settled``.
    due, soon, soon_clear : Out(blocks)
        Bit g: group g's pulse time has come; it comes within ``soon``, ``soon_clear`` cycles.
    late : Out(1)
        The group pulsing this cycle pulses after its time.
    memory_free : Out(blocks)
        Bit g: group g's memory may change (counted from its pulse, a retake and RST_ACTIVE's fall).
    rst_over : Out(blocks)
        Bit g: RST_ACTIVE may no longer be high for group g's last pulse.
    rst_over_any : Out(1)
        The same, for the last pulse of any group.
    """

    def __init__(self, dmd, *, soon, soon_clear):
        self._dmd, self._soon, self._soon_clear = dmd, soon, soon_clear
        groups = dmd.blocks
        super().__init__({
            "regs": In(Registers),
            "now": In(TIME_BITS),
            "pulse": In(event(data.StructLayout({"group": group_bits(dmd), "delay": TIME_BITS}))),
            "trigger": In(event(TIME_BITS)),
            "active": In(groups),
            "retake": In(event(TIME_BITS)),
            "fell": In(event(data.StructLayout({"groups": groups, "settled": TIME_BITS}))),
            "due": Out(groups),
            "soon": Out(groups),
            "soon_clear": Out(groups),
            "late": Out(1),
            "memory_free": Out(groups),
            "rst_over": Out(groups),
            "rst_over_any": Out(1),
        })

    def elaborate(self, platform):
        m = Module()
        regs, now = self.regs, self.now
        G = self._dmd.blocks

        def per_group(name, init=0):
            return Array(Signal(TIME_BITS, name=f"{name}{g}", init=init) for g in range(G))
        pulse_at = per_group("pulse_at")
        writable = per_group("writable", INIT_TO_DVALID)
        rst_free = per_group("rst_free")
        rst_any = Signal(TIME_BITS)

        for g in range(G):
            m.d.comb += [
                self.due[g].eq(diff(pulse_at[g], now) <= 0),
                self.soon[g].eq(diff(pulse_at[g], now) < self._soon),
                self.soon_clear[g].eq(diff(pulse_at[g], now) < self._soon_clear),
                self.memory_free[g].eq(diff(writable[g], now) <= 0),
                self.rst_over[g].eq(diff(rst_free[g], now) <= 0),
            ]
        m.d.comb += self.rst_over_any.eq(diff(rst_any, now) <= 0)

        p = self.pulse.payload.group
        with m.If(self.pulse.valid):
            m.d.comb += self.late.eq(diff(pulse_at[p], now) < 0)
            m.d.sync += [
                pulse_at[p].eq(now + self.pulse.payload.delay),
                writable[p].eq(now + regs.t_rst + regs.t_settle),
                rst_free[p].eq(now + regs.t_rst),
                rst_any.eq(now + regs.t_rst),
            ]
        with m.If(self.trigger.valid):
            for g in range(G):
                with m.If(self.active[g]):
                    m.d.sync += pulse_at[g].eq(self.trigger.payload + regs.stagger * g)

        lead = self.retake.payload
        settled = self.fell.payload.settled
        for g in range(G):
            # a retake: no sooner than its lead; then RST_ACTIVE's fall: no sooner than settled
            base = Mux(self.retake.valid & (diff(writable[g], lead) < 0), lead, writable[g])
            with m.If(self.retake.valid):
                m.d.sync += writable[g].eq(base)
            with m.If(self.fell.valid & self.fell.payload.groups[g] & (diff(base, settled) < 0)):
                m.d.sync += writable[g].eq(settled)
        return m
