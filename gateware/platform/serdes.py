"""4:1 output serialisers for DCLK 400 MHz: four bits per 200 MHz ``dmd`` cycle on an 800 Mb/s lane.

At DCLK 400 MHz every DIN pin carries four bits per ``dmd`` cycle (two DCLK cycles, both edges),
and DVALID likewise. Each such lane is an OSERDES2 in 4:1 SDR mode, its parallel side clocked by
``dmd`` and its serial side by an 800 MHz I/O clock from a BUFPLL (with the strobe that loads the
four bits once per ``dmd`` cycle). The Spartan-6 OSERDES2 sends D1 first, then D2, D3, D4 (its
shift register loads D1..D4 on the strobe and shifts toward D1: Xilinx's simulation model of the
primitive); :func:`lane_bits` puts the interface's edge 0 on D1.

DCLK is a lane too, sending ``1 0 1 0`` each ``dmd`` cycle from a second BUFPLL whose I/O clock
runs half a bit (625 ps, 90 degrees of DCLK) later than the data's, so that every DCLK edge falls
in the middle of a data bit and DCLK's rising edge in the middle of edge 0's bit.

:class:`Oserdes4` is the vendor primitive; ``sim/models/oserdes2_model.py`` is its behavioural
model, against which ``tests/test_platform_serdes.py`` checks the bits on each lane, in order, at
each DCLK edge.
"""

from amaranth import Elaboratable, Instance, Module

__all__ = ["Oserdes4", "DCLK_BITS", "lane_bits"]

#: DCLK's four bits per ``dmd`` cycle (sent half a bit after the data lanes).
DCLK_BITS = (1, 0, 1, 0)


def lane_bits(edges, pin):
    """The four bits of data pin ``pin`` in one ``dmd`` cycle, in the order they leave (D1 first):
    ``edges`` is a pin bus's :class:`~amaranth.lib.data.ArrayLayout` of per-edge values (edge 0 is
    the first DCLK cycle's rising edge), each a value with one bit per pin."""
    return [edges[edge][pin] for edge in range(4)]


class Oserdes4(Elaboratable):
    """One OSERDES2 lane, 4:1 SDR, single-ended output into the differential buffer that follows.

    Parameters
    ----------
    bits : list of 4 Values
        The bits of one ``dmd`` cycle, first out first (they drive D1..D4).
    ioclk, strobe : Signal
        The BUFPLL's I/O clock and serdes strobe.
    reset : Signal
        The ``dmd`` domain's reset.
    out : Signal
        The serial output, to the pin's output buffer.
    """

    def __init__(self, bits, *, ioclk, strobe, reset, out):
        assert len(bits) == 4
        self.bits, self.ioclk, self.strobe, self.reset, self.out = bits, ioclk, strobe, reset, out

    def elaborate(self, platform):
        from amaranth import ClockSignal
        m = Module()
        m.submodules.oserdes = Instance(
            "OSERDES2",
            p_DATA_WIDTH=4, p_DATA_RATE_OQ="SDR", p_DATA_RATE_OT="SDR", p_SERDES_MODE="NONE",
            p_OUTPUT_MODE="SINGLE_ENDED", p_BYPASS_GCLK_FF="FALSE", p_TRAIN_PATTERN=0,
            i_CLK0=self.ioclk, i_CLK1=0, i_CLKDIV=ClockSignal("dmd"), i_IOCE=self.strobe,
            i_OCE=1, i_RST=self.reset, i_TRAIN=0, i_TCE=1,
            i_D1=self.bits[0], i_D2=self.bits[1], i_D3=self.bits[2], i_D4=self.bits[3],
            i_T1=0, i_T2=0, i_T3=0, i_T4=0,
            i_SHIFTIN1=1, i_SHIFTIN2=1, i_SHIFTIN3=1, i_SHIFTIN4=1,
            o_OQ=self.out,
        )
        return m
