"""Behavioural model of the Spartan-6 OSERDES2 in 4:1 SDR mode (what :mod:`gateware.platform.serdes`
instantiates), for simulation without the vendor's libraries.

As Xilinx's simulation model of the primitive: D1..D4 are registered on the parallel clock
(``dmd``, CLKDIV); on the I/O clock edge after the BUFPLL's strobe the four bits load into the
shift register and D1 leaves; D2, D3 and D4 follow on the next three I/O clock edges. The output
is registered on the I/O clock.
"""

from amaranth import Module, Signal
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

__all__ = ["Oserdes2Model"]


class Oserdes2Model(wiring.Component):
    """One 4:1 lane.

    Parameters
    ----------
    io_domain : str
        The I/O clock's domain (four times the ``dmd`` clock, phase-aligned with it).

    Members
    -------
    d : In(4)
        D1..D4 in bits 0..3 (``dmd``).
    strobe : In(1)
        The BUFPLL's serdes strobe (``io_domain``): high for one I/O clock cycle per ``dmd`` cycle.
    out : Out(1)
        The serial output (``io_domain``).
    """

    d: In(4)
    strobe: In(1)
    out: Out(1)

    def __init__(self, io_domain="io"):
        self._io = io_domain
        super().__init__()

    def elaborate(self, platform):
        m = Module()
        io = m.d[self._io]
        held = Signal(4)              # the CLKDIV register bank
        ioce = Signal()
        shift = Signal(4)
        m.d.dmd += held.eq(self.d)
        io += ioce.eq(self.strobe)
        with m.If(ioce):
            io += [shift.eq(held), self.out.eq(held[0])]
        with m.Else():
            io += [shift.eq(shift >> 1), self.out.eq(shift[1])]
        return m
