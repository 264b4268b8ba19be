"""PHY management: reset the PHY, then poll its status over MDIO (IEEE 802.3 clause 22).

The status reply reports whether the Ethernet link is up and at what speed; this block keeps
those two facts current by reading the 88E1111's PHY-specific status register in a loop.
"""

from amaranth import Cat, Const, Module, Signal
from amaranth.lib import data, wiring
from amaranth.lib.wiring import In, Out

from spec.facts import PHY

__all__ = ["LinkStatus", "StatusPoller"]


class LinkStatus(data.Struct):
    """What the status reply says about the Ethernet link."""
    up: 1
    speed: 2        # 88E1111 encoding: 2 = 1000, 1 = 100, 0 = 10 Mb/s
    resolved: 1
    polls: 16       # completed reads, so a stuck management bus is visible


class StatusPoller(wiring.Component):
    """Hold the PHY in reset, release it, then read its status register forever.

    Parameters
    ----------
    clk_freq : float
        Frequency of the ``sync`` domain in Hz.
    phy_address : int
        The PHY's MDIO address.
    mdc_freq : float
        MDC frequency; at most 2.5 MHz (IEEE 802.3).
    reset_cycles, settle_cycles : int, optional
        Override the reset and post-reset waits (tests use short ones).

    Members
    -------
    phy_reset_n : Out(1)
        PHY reset, active low.
    mdc : Out(1)
        Management clock.
    mdio_o, mdio_oe : Out(1)
        Management data driven by us, and its output enable.
    mdio_i : In(1)
        Management data as read at the pin.
    status : Out(LinkStatus)
        The latest status read.
    """

    def __init__(self, clk_freq, *, phy_address=int(PHY["phy_address"].value),
                 mdc_freq=PHY["mdc_max"].value, reset_cycles=None, settle_cycles=None):
        assert mdc_freq <= PHY["mdc_max"].value
        self._half = max(1, int(-(-clk_freq // (2 * mdc_freq))))   # sync cycles per MDC half period
        self._phy_address = phy_address
        self._reset_cycles = reset_cycles or int(PHY["reset_low"].value * clk_freq)
        self._settle_cycles = settle_cycles or int(PHY["reset_to_mdio"].value * clk_freq)
        super().__init__({
            "phy_reset_n": Out(1),
            "mdc": Out(1),
            "mdio_o": Out(1),
            "mdio_oe": Out(1),
            "mdio_i": In(1),
            "status": Out(LinkStatus),
        })

    def read_frame(self, register):
        """The 32 bits we drive for a read (preamble excluded), MSB first: ST, OP, PHYAD, REGAD."""
        return (0b01 << 12) | (0b10 << 10) | (self._phy_address << 5) | register

    def elaborate(self, platform):
        m = Module()
        register = int(PHY["reg_status"].value)

        # Frame: 32 preamble ones, 14 bits ST/OP/PHYAD/REGAD we drive, 2 turnaround bits
        # released, 16 data bits from the PHY, one idle bit. 65 MDC periods in all.
        # the header LSB-first, so that bit 32 + i of the frame is header bit i
        header = Const(int(f"{self.read_frame(register):014b}"[::-1], 2), 14)
        bit = Signal(range(66))
        phase = Signal(range(self._half))
        rising = Signal()       # MDC is about to rise: the PHY samples what we drive, we sample it
        shift = Signal(16)

        wait = Signal(range(max(self._reset_cycles, self._settle_cycles) + 1))
        with m.FSM():
            with m.State("RESET"):
                m.d.sync += wait.eq(wait + 1)
                with m.If(wait == self._reset_cycles):
                    m.d.sync += [wait.eq(0), self.phy_reset_n.eq(1)]
                    m.next = "SETTLE"
            with m.State("SETTLE"):
                m.d.sync += wait.eq(wait + 1)
                with m.If(wait == self._settle_cycles):
                    m.next = "FRAME"
            with m.State("FRAME"):
                m.d.sync += phase.eq(phase + 1)
                m.d.comb += rising.eq((phase == self._half - 1) & ~self.mdc)
                with m.If(phase == self._half - 1):
                    m.d.sync += [phase.eq(0), self.mdc.eq(~self.mdc)]
                    # On the falling edge move to the next bit: data changes while MDC is low.
                    with m.If(self.mdc):
                        m.d.sync += bit.eq(bit + 1)
                        with m.If(bit == 64):
                            m.d.sync += bit.eq(0)
                            m.d.sync += [
                                self.status.up.eq(shift[int(PHY["status_link_bit"].value)]),
                                self.status.speed.eq(shift[int(PHY["status_speed_lsb"].value):][:2]),
                                self.status.resolved.eq(shift[int(PHY["status_resolved_bit"].value)]),
                                self.status.polls.eq(self.status.polls + 1),
                            ]
                with m.If(rising & (bit >= 48) & (bit < 64)):
                    m.d.sync += shift.eq(Cat(self.mdio_i, shift[:-1]))

        # Drive: preamble ones (bits 0-31), then the header MSB first (32-45); release after.
        with m.If(bit < 32):
            m.d.comb += [self.mdio_o.eq(1), self.mdio_oe.eq(1)]
        with m.Elif(bit < 46):
            m.d.comb += [self.mdio_o.eq(header.bit_select((bit - 32)[:4], 1)), self.mdio_oe.eq(1)]
        return m
