"""Trigger input: what starts a frame, as a one-cycle strobe in the ``dmd`` domain.

The TTL trigger and the sync input are asynchronous: each goes through a
:class:`amaranth.lib.cdc.FFSynchronizer`. On Spartan-6 the platform layer places the
synchroniser's first flip-flop in the input pad's IOB register (``IOB = TRUE`` on the pin's
input flip-flop in the UCF) so that the pad-to-register delay is fixed; this module stays free
of vendor primitives. A rising edge of the selected source gives one strobe. The periodic timer
is a countdown (:mod:`gateware.countdown`), reloaded with the period at each strobe.
"""

from amaranth import Module, Signal
from amaranth.lib import wiring
from amaranth.lib.cdc import FFSynchronizer
from amaranth.lib.wiring import In, Out

from ..countdown import Countdown
from ..registers import DURATION_BITS, TriggerMode

__all__ = ["Trigger", "PIN_TO_STROBE", "SYNC_STAGES"]

#: Synchroniser depth (two flip-flops: the first in the IOB).
SYNC_STAGES = 2
#: Cycles from the first clock edge that samples a new pin level to the strobe (see tests).
PIN_TO_STROBE = SYNC_STAGES


class Trigger(wiring.Component):
    """Trigger source selection.

    Members
    -------
    mode : In(TriggerMode)
    period : In(DURATION_BITS)
        Strobe period in :attr:`TriggerMode.PERIODIC`: the first strobe ``period - 1`` cycles
        after ``run`` rose, then one every ``period`` cycles (a new period takes effect from the
        next strobe).
    run : In(1)
        The periodic timer runs while high.
    pin : In(1)
        TTL trigger input (asynchronous).
    sync_in : In(1)
        Sync input from a sync master (asynchronous).
    soft : In(1)
        Software trigger: a one-cycle pulse in this domain.
    strobe : Out(1)
        One cycle per trigger.
    """
    mode: In(TriggerMode)
    period: In(DURATION_BITS)
    run: In(1)
    pin: In(1)
    sync_in: In(1)
    soft: In(1)
    strobe: Out(1)

    def elaborate(self, platform):
        m = Module()
        edges = {}
        for name in ("pin", "sync_in"):
            synced = Signal(name=f"{name}_synced")
            last = Signal(name=f"{name}_last")
            m.submodules[f"{name}_sync"] = FFSynchronizer(getattr(self, name), synced, stages=SYNC_STAGES)
            m.d.sync += last.eq(synced)
            edges[name] = synced & ~last

        # the period counted from the cycle before the timer runs (its first strobe is the
        # period's last cycle), and again from each strobe
        m.submodules.timer = timer = Countdown(DURATION_BITS, flags="settled")
        tick = self.run & timer.ends
        m.d.comb += [timer.load.eq(~self.run | tick), timer.value.eq(self.period)]

        with m.Switch(self.mode):
            with m.Case(TriggerMode.EXTERNAL):
                m.d.comb += self.strobe.eq(edges["pin"])
            with m.Case(TriggerMode.SYNC):
                m.d.comb += self.strobe.eq(edges["sync_in"])
            with m.Case(TriggerMode.PERIODIC):
                m.d.comb += self.strobe.eq(tick)
            with m.Case(TriggerMode.SOFTWARE):
                m.d.comb += self.strobe.eq(self.soft)
        return m
