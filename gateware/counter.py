"""Event counters with short carry chains.

A counter of ``width`` bits is held in limbs of at most :data:`~gateware.countdown.LIMB_BITS`
bits. A limb steps when the count steps and every limb below it is at its largest value, which
each limb keeps as a registered flag; so no carry chain is longer than a limb, and the count is
exact on every cycle (a limb and the ones below it wrap in the same cycle).
"""

from amaranth import Const, Module, Signal
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from .countdown import LIMB_BITS

__all__ = ["Counter"]


class Counter(wiring.Component):
    """A wrapping up-counter.

    Parameters
    ----------
    width : int
        Bits of the count.
    limb_bits : int
        Bits of a limb (the longest carry chain).
    restart_value : int
        The count after ``restart``.

    Members
    -------
    inc : In(1)
        Count one this cycle.
    restart : In(1)
        Start again from ``restart_value`` (over ``inc``).
    count : Out(width)
        The events counted before this cycle, modulo ``2**width``.
    """

    def __init__(self, width, *, limb_bits=LIMB_BITS, restart_value=0):
        self._width, self._limb_bits, self._restart = width, limb_bits, restart_value % (1 << width)
        super().__init__({"inc": In(1), "restart": In(1), "count": Out(width)})

    def elaborate(self, platform):
        m = Module()
        bounds = [(lo, min(lo + self._limb_bits, self._width)) for lo in range(0, self._width, self._limb_bits)]
        top = [(1 << (hi - lo)) - 1 for lo, hi in bounds]
        limbs = [self.count[lo:hi] for lo, hi in bounds]
        full = [Signal(name=f"full{i}") for i in range(len(limbs))]
        below = Const(1)                       # every limb below this one is at its top
        for (lo, _hi), limb, at_top, z in zip(bounds, limbs, top, full, strict=True):
            start = (self._restart >> lo) & at_top
            with m.If(self.restart):
                m.d.sync += [limb.eq(start), z.eq(start == at_top)]
            with m.Elif(self.inc & below):
                # it steps: at its top next if it is one below now (else it wraps, or climbs)
                m.d.sync += [limb.eq(limb + 1), z.eq(limb == at_top - 1)]
            below = below & z
        return m
