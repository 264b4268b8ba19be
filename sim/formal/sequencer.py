"""The DLPC410's rules as formal properties of the sequencer: no command during INIT_ACTIVE, no
clocking pulse while RST_ACTIVE is high.

The top is :class:`gateware.dlpc410.sequencer.Sequencer` on :data:`DMD` (two buses, two DCLK
cycles a row, two blocks of four rows) at one beat, every input free: registers, triggers, the
store's frames, words and occupancy, and the controller's pins, ECP2_FINISHED, INIT_ACTIVE and
RST_ACTIVE included: the controller may start up, initialise again mid-run, and raise or drop
RST_ACTIVE at any time.

Properties, white box so that k-induction closes (a part's signal is copied out while the
sequencer is elaborated):

* the sequencer drives a command (ROWMD or BLKMD not no-op) only when ECP2_FINISHED was high and
  INIT_ACTIVE low at the pins three cycles earlier (the two cycles of its synchroniser and the
  register of ``running``: the soonest it can know); otherwise only the training pattern is on
  DVALID and the data pins. ``running`` is high exactly when the pins showed the controller
  ready three cycles earlier;
* with the strict reading (``strict_rst``), the bus decides a clocking pulse (on the pins the
  next cycle) only when RST_ACTIVE was low at the pins two cycles earlier (its synchroniser); the
  loose reading lets another group pulse while RST_ACTIVE is high;
* after a clocking pulse, no row load or block clear reaches the pins before ``t_rst + t_settle``
  cycles have passed, and, when RST_ACTIVE rises within ``t_rst`` of the pulse, none while it is
  high nor before ``t_settle`` cycles after it fell (bounded: global pulses, registers held, the
  first load's wait shortened so that a pulse and the loads after it are reached).
"""

import dataclasses
from contextlib import contextmanager

from amaranth import Mux, Signal
from amaranth.hdl import Assert, Assume, Fragment

from spec.facts import TEST_DMD

from .harness import Check, FormalTop

__all__ = ["sequencer_checks", "rst_top", "settle_top", "DMD"]

#: Two words a row on two buses (two DCLK cycles a row at one beat, the fewest the sequencer
#: takes), eight rows in two blocks: the smallest geometry the sequencer builds for.
DMD = dataclasses.replace(TEST_DMD, name="formal 128x8", rows=8, blocks=2, rows_per_block=4)


@contextmanager
def _watched(part, member, out):
    """While the sequencer is elaborated, its part ``part`` (a class name in
    :mod:`gateware.dlpc410.sequencer`, made inside the sequencer's ``elaborate``) copies its
    member ``member`` (dotted: ``"pulse.valid"``) out to ``out``, for a property."""
    from gateware.dlpc410 import sequencer
    original = getattr(sequencer, part)

    class Watched(original):
        def elaborate(self, platform):
            m = super().elaborate(platform)
            value = self
            for name in member.split("."):
                value = getattr(value, name)
            m.d.comb += out.eq(value)
            return m

    setattr(sequencer, part, Watched)
    try:
        yield
    finally:
        setattr(sequencer, part, original)


def _no_command_during_init(running):
    from gateware.dlpc410.interface import BlockMode, RowMode

    def prop(m, top):
        pins = top.dut.pins
        # ready at the pins (ECP2_FINISHED high, INIT_ACTIVE low), one, two and three cycles ago
        ready = pins.ecp2_finished & ~pins.init_active
        ready_1, ready_2, ready_3 = Signal(), Signal(), Signal()
        m.d.sync += [ready_1.eq(ready), ready_2.eq(ready_1), ready_3.eq(ready_2)]
        command = (pins.rowmd != RowMode.NOOP) | (pins.blkmd != BlockMode.NOOP)
        m.d.comb += [
            Assert(~command | ready_3, "a command while INIT_ACTIVE was high (or ECP2_FINISHED low)"),
            Assert(running == ready_3, "running other than the controller's state three cycles ago"),
        ]

    return prop


def _no_pulse_while_rst_active(pulse, latency):
    def prop(m, top):
        seen = top.dut.pins.rst_active
        for k in range(latency):
            later = Signal(name=f"rst_{k + 1}")
            m.d.sync += later.eq(seen)
            seen = later
        m.d.comb += Assert(~pulse | ~seen | ~top.dut.regs.strict_rst, "a clocking pulse while RST_ACTIVE was high")

    return prop


def _settle_after_pulse(pulse, extra):
    from gateware.dlpc410.interface import BlockMode, RowMode
    from gateware.registers import ResetMode

    def prop(m, top):
        pins, regs = top.dut.pins, top.dut.regs
        # the environment: global pulses, registers held from the start, times not too short for
        # RST_ACTIVE's synchroniser (a real plan's are hundreds of cycles)
        held, first = Signal.like(regs), Signal(init=1)
        m.d.sync += [held.eq(regs), first.eq(0)]
        m.d.comb += [Assume(first | (regs.as_value() == held.as_value())),
                     Assume(regs.reset_mode == ResetMode.GLOBAL),
                     Assume((regs.t_rst >= 4) & (regs.t_settle >= 4))]
        # on the pins: the pulse's row cycle starts the cycle after the decision
        on_pins = Signal()
        m.d.sync += on_pins.eq(pulse)
        write = (pins.rowmd != RowMode.NOOP) | (pins.blkmd == BlockMode.CLEAR)
        pulsed, rose, fell = Signal(), Signal(), Signal()
        since_pulse, since_fall = Signal(16), Signal(16)
        rst = pins.rst_active
        with m.If(on_pins):
            m.d.sync += [pulsed.eq(1), since_pulse.eq(1), rose.eq(rst), fell.eq(0)]
        with m.Else():
            with m.If(since_pulse != 2**16 - 1):
                m.d.sync += since_pulse.eq(since_pulse + 1)
            with m.If(pulsed & ~rose & rst & (since_pulse <= regs.t_rst)):
                m.d.sync += rose.eq(1)
            with m.If(rose & ~fell & ~rst):
                m.d.sync += [fell.eq(1), since_fall.eq(1)]
            with m.Elif(fell & (since_fall != 2**16 - 1)):
                m.d.sync += since_fall.eq(since_fall + 1)
        # ``since_*`` counts the cycles after the pulse's first pins cycle (0 on it) and after
        # the fall (0 on the first cycle RST_ACTIVE is low)
        age = Mux(on_pins, 0, since_pulse)
        risen = rose | (on_pins & rst)
        m.d.comb += [
            Assert(~(write & pulsed) | (age >= regs.t_rst + regs.t_settle + extra),
                   "a load sooner than t_rst + t_settle after a pulse"),
            Assert(~(write & risen & ~(fell | (rose & ~rst))),
                   "a load while RST_ACTIVE was high after a pulse"),
            Assert(~(write & fell) | (since_fall >= regs.t_settle),
                   "a load sooner than t_settle after RST_ACTIVE fell"),
        ]

    return prop


def _sequencer_top(part, member, prop, init_to_dvalid=None):
    """The sequencer with ``prop(watched)`` as its property, ``watched`` a copy of the member
    ``member`` of its part ``part`` (:func:`_watched`); ``init_to_dvalid``: a shorter wait before
    the first load than the facts' 64 clocks, so that a bounded check reaches a pulse within a few
    tens of steps (15 with 2)."""
    from gateware.dlpc410 import planner
    from gateware.dlpc410.sequencer import Sequencer
    watched = Signal()
    original = planner.INIT_TO_DVALID
    planner.INIT_TO_DVALID = original if init_to_dvalid is None else init_to_dvalid
    try:
        with _watched(part, member, watched):
            return Fragment.get(FormalTop(Sequencer(DMD, beats=1, store_words=1), [prop(watched)]), None)
    finally:
        planner.INIT_TO_DVALID = original


def _init_top():
    return _sequencer_top("Init", "running", _no_command_during_init)


def rst_top(latency=2, init_to_dvalid=None):
    """The RST_ACTIVE property's top; ``latency``: cycles from the pins to the decision it allows
    (the synchroniser's two; one is too few, and the check must then fail)."""
    return _sequencer_top("Bus", "pulse.valid", lambda pulse: _no_pulse_while_rst_active(pulse, latency),
                          init_to_dvalid)


def settle_top(init_to_dvalid=2, extra=0):
    """The settle property's top. ``extra``: claim this many cycles more after a pulse than the
    sequencer keeps (1: the check must fail, for the sequencer loads right at ``t_rst +
    t_settle``)."""
    return _sequencer_top("Bus", "pulse.valid", lambda pulse: _settle_after_pulse(pulse, extra), init_to_dvalid)


def sequencer_checks():
    return [Check("no command during INIT_ACTIVE", "Sequencer", _init_top, depth=12, induction=4, quick=4),
            Check("no clocking pulse while RST_ACTIVE is high", "Sequencer", rst_top, depth=12, induction=4,
                  quick=4),
            Check("no load within the settle time after a pulse and after RST_ACTIVE fell", "Sequencer",
                  settle_top, depth=36, quick=28)]
