"""Clock-domain crossings the amaranth standard library does not have.

Every crossing in the design goes through :class:`amaranth.lib.fifo.AsyncFIFO`, a
:mod:`amaranth.lib.cdc` synchroniser, or :class:`CountSynchronizer` below (built on
:class:`~amaranth.lib.cdc.FFSynchronizer`).
"""

from amaranth import Module, Signal
from amaranth.lib import wiring
from amaranth.lib.cdc import FFSynchronizer
from amaranth.lib.wiring import In, Out

__all__ = ["CountSynchronizer"]


def _gray(value):
    return value ^ (value >> 1)


def _from_gray(gray):
    """Binary bit ``i`` is the XOR of Gray bits ``i`` and up: each one a balanced tree (two LUT
    levels for 32 bits), not a chain through the bits above it."""
    return [gray[i:].xor() for i in range(len(gray))]


class CountSynchronizer(wiring.Component):
    """Carry a counter into another clock domain.

    The counter is registered in Gray code in its own domain and synchronised bit by bit; since
    it steps by at most one per source cycle, only one bit changes at a time and the reader
    sees either the old or the new count, never a mix.

    Parameters
    ----------
    width : int
    i_domain, o_domain : str

    Members
    -------
    i : In(width)
        The counter, in ``i_domain``; it must step by 0 or +1 per cycle (wrapping).
    o : Out(width)
        Its value in ``o_domain``, four ``o_domain`` cycles or so behind.
    """

    def __init__(self, width, *, i_domain, o_domain):
        self._i_domain, self._o_domain = i_domain, o_domain
        super().__init__({"i": In(width), "o": Out(width)})

    def elaborate(self, platform):
        m = Module()
        gray_i = Signal.like(self.i)
        gray_o = Signal.like(self.i)
        m.d[self._i_domain] += gray_i.eq(_gray(self.i))
        m.submodules.sync = FFSynchronizer(gray_i, gray_o, o_domain=self._o_domain)
        for i, bit in enumerate(_from_gray(gray_o)):
            m.d[self._o_domain] += self.o[i].eq(bit)
        return m
