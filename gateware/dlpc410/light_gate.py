"""The light gate: switches a modulated light source during gated planes.

Binary PWM cannot make a plane shorter than the mirrors' reload; a gated plane lasts the
shortest legal time (``gated_time``) and weighs its light by switching the source instead: on
``light_lead`` cycles after the plane's pulse leaves (the mirrors settled), for the plane's own
``light_times[e]``, off again before the next pulse (:func:`spec.records.register_faults`).

Two countdowns (:mod:`gateware.countdown`), as the camera trigger's: the on-time's is loaded as
the lead's ends, so each edge leaves on its exact cycle with no sum formed. With no plane gated
the gate stays on: the source lights every plane through its mirrors' transitions, as plain
PWM wants.
"""

from amaranth import Array, Module, Signal
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from ..countdown import Countdown
from ..registers import Registers

__all__ = ["LightGate"]


class LightGate(wiring.Component):
    """The gate pin's drive (``sync``).

    Members
    -------
    regs : In(Registers)
        ``gated_planes``, ``light_lead`` (at least 2 when a plane is gated), ``light_times``.
    pulse : In(1)
        A plane's clocking pulse (not a dark one) is applied this cycle (its command reaches the
        pins the next cycle).
    exponent : In(3)
        With ``pulse``: the plane's weight exponent.
    out : Out(1)
        Registered like the command pins: for a gated plane, high from ``light_lead`` cycles after
        its pulse leaves, for ``light_times[exponent]`` cycles; low from a gated plane's pulse on
        otherwise; high from an ungated plane's pulse on, and while no plane is gated.
    """

    regs: In(Registers)
    pulse: In(1)
    exponent: In(3)
    out: Out(1)

    def elaborate(self, platform):
        m = Module()
        regs = self.regs
        m.submodules.lead = lead = Countdown(len(regs.light_lead), flags="given")
        m.submodules.light = light = Countdown(len(regs.light_times[0]), flags="settled")
        # (the registers hold still while frames play: their flags and choices are registered)
        none, on_time = Signal(), Signal.like(regs.light_times[0])
        m.d.sync += none.eq(regs.gated_planes == 0)
        lead_flags = lead.flags_registered(m, regs.light_lead, "lead_flags")
        gated = regs.gated_planes.bit_select(self.exponent, 1)
        waiting, lit = Signal(), Signal()
        m.d.comb += [lead.value.eq(regs.light_lead), lead.load_flags.eq(lead_flags), light.value.eq(on_time)]
        with m.If(none):
            m.d.sync += [waiting.eq(0), lit.eq(0), self.out.eq(1)]
        with m.Elif(self.pulse):
            # (the on-time is chosen now and holds still until the lead's end loads it)
            m.d.comb += lead.load.eq(gated)
            m.d.sync += [waiting.eq(gated), lit.eq(0), self.out.eq(~gated),
                         on_time.eq(Array(regs.light_times)[self.exponent])]
        with m.Elif(waiting & lead.ends):
            m.d.comb += light.load.eq(1)
            m.d.sync += [waiting.eq(0), lit.eq(on_time != 0), self.out.eq(on_time != 0)]
        with m.Elif(lit & light.ends):
            m.d.sync += [lit.eq(0), self.out.eq(0)]
        return m
