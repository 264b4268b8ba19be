"""The DLPC410 initialisation rule as a formal property of the sequencer: no command during INIT_ACTIVE.

The top is :class:`gateware.dlpc410.sequencer.Sequencer` on :data:`DMD` (two buses, two DCLK
cycles a row, two blocks of four rows) at one beat, every input free: registers, triggers, the
store's frames, words and occupancy, and the controller's pins, ECP2_FINISHED and INIT_ACTIVE
included: the controller may start up, and initialise again mid-run, at any time.

Property: the sequencer drives a command (ROWMD or BLKMD not no-op) only when ECP2_FINISHED was
high and INIT_ACTIVE low at the pins three cycles earlier (the two cycles of its synchroniser and
the register of ``running``: the soonest it can know); otherwise only the training pattern is on
DVALID and the data pins. White box, so that k-induction closes: the sequencer's ``running`` is
high exactly when the pins showed the controller ready three cycles earlier.
"""

import dataclasses
from contextlib import contextmanager

from amaranth import Signal
from amaranth.hdl import Assert, Fragment

from spec.facts import TEST_DMD

from .harness import Check, FormalTop

__all__ = ["sequencer_checks", "DMD"]

#: Two words a row on two buses (two DCLK cycles a row at one beat, the fewest the sequencer
#: takes), eight rows in two blocks: the smallest geometry the sequencer builds for.
DMD = dataclasses.replace(TEST_DMD, name="formal 128x8", rows=8, blocks=2, rows_per_block=4)


@contextmanager
def _watched_init(running):
    """While the sequencer is elaborated, its start-up part copies ``running`` out to the
    property (the part is made inside the sequencer's ``elaborate``)."""
    from gateware.dlpc410 import sequencer
    original = sequencer.Init

    class WatchedInit(original):
        def elaborate(self, platform):
            m = super().elaborate(platform)
            m.d.comb += running.eq(self.running)
            return m

    sequencer.Init = WatchedInit
    try:
        yield
    finally:
        sequencer.Init = original


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


def _top():
    from gateware.dlpc410.sequencer import Sequencer
    running = Signal()
    with _watched_init(running):
        top = FormalTop(Sequencer(DMD, beats=1, store_words=1), [_no_command_during_init(running)])
        return Fragment.get(top, None)


def sequencer_checks():
    return [Check("no command during INIT_ACTIVE", "Sequencer", _top, depth=12, induction=4, quick=4)]
