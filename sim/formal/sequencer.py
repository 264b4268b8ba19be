"""The DLPC410 start-up rule as a formal property of the sequencer: no command during INIT_ACTIVE.

The top is :class:`gateware.dlpc410.sequencer.Sequencer` on :data:`DMD` (two buses, two DCLK
cycles a row, two blocks of four rows) at one beat, every input free: registers, triggers, the
store's frames, words and occupancy, and the controller's pins, but for ECP2_FINISHED and
INIT_ACTIVE, which follow the controller's start-up (DLPC410 datasheet, DLPC910): once
ECP2_FINISHED is high and INIT_ACTIVE low they stay so. INIT_ACTIVE rising again mid-run is a
controller fault the sequencer does not handle yet (it keeps running), so it is left out.

Property: the sequencer drives no command (ROWMD and BLKMD both no-op) until ECP2_FINISHED has
been high and INIT_ACTIVE low at the pins for the two cycles of its synchroniser; before that
only the training pattern is on DVALID and the data pins. White box, so that k-induction
closes: the sequencer's ``running`` is high only once the pins have shown the controller ready.
"""

import dataclasses
from contextlib import contextmanager

from amaranth import Signal
from amaranth.hdl import Assert, Assume, Fragment

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
        # ready at the pins (ECP2_FINISHED high, INIT_ACTIVE low), one and two cycles ago
        ready = pins.ecp2_finished & ~pins.init_active
        ready_1, ready_2 = Signal(), Signal()
        m.d.sync += [ready_1.eq(ready), ready_2.eq(ready_1)]
        # the controller's start-up: once ready, it stays ready
        m.d.comb += Assume(~ready_1 | ready)
        command = (pins.rowmd != RowMode.NOOP) | (pins.blkmd != BlockMode.NOOP)
        m.d.comb += [
            Assert(~command | ready_2, "a command before INIT_ACTIVE fell (or before ECP2_FINISHED)"),
            Assert(~running | ready_2, "running before the controller was ready"),
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
