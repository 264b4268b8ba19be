"""Clock-domain crossings the amaranth standard library does not have.

Every crossing in the design goes through :class:`amaranth.lib.fifo.AsyncFIFO`, a
:mod:`amaranth.lib.cdc` synchroniser, or :class:`CountSynchronizer` below (built on
:class:`~amaranth.lib.cdc.FFSynchronizer`).
"""

from amaranth import Cat, Module, Signal
from amaranth.lib import wiring
from amaranth.lib.cdc import FFSynchronizer
from amaranth.lib.wiring import In, Out

__all__ = ["CountSynchronizer"]


def _gray(value):
    return value ^ (value >> 1)


#: Gray bits per chunk of the decode's first stage (one LUT6 each).
_CHUNK = 6


def _from_gray(m, domain, gray):
    """Binary bit ``i`` is the XOR of Gray bits ``i`` and up, in two registered stages so that
    no synthesis can chain it through the bits above (it does, to share logic, when it sees the
    whole of it: 14 LUT levels for 32 bits): first, per chunk of :data:`_CHUNK` bits, each
    bit's XOR up to its chunk's top (one LUT level); then each bit's with every chunk above
    (two). Returns the binary value, two cycles after ``gray``."""
    width = len(gray)
    chunks = range(0, width, _CHUNK)
    within = Signal(width)
    m.d[domain] += [within[i].eq(gray[i:min(width, i // _CHUNK * _CHUNK + _CHUNK)].xor()) for i in range(width)]
    above = {lo: [within[hi] for hi in chunks if hi > lo] for lo in chunks}
    binary = Signal(width)
    m.d[domain] += [binary[i].eq(Cat(within[i], *above[i // _CHUNK * _CHUNK]).xor()) for i in range(width)]
    return binary


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
        Its value in ``o_domain``, five ``o_domain`` cycles or so behind (the synchroniser's two,
        the decode's two).
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
        m.d.comb += self.o.eq(_from_gray(m, self._o_domain, gray_o))
        return m
