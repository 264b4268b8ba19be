"""The SVEC's Ethernet from the MAC to the line, with a link partner's transceiver on the line:
the top that :mod:`sim.tb.sfp_link_tb` drives.

* The board side: :class:`gateware.platform.pins.SfpPhy` (the GTP lane, our PCS, the transmit
  elastic buffer) under the MAC's :class:`~gateware.mac.path.ReceivePath` and
  :class:`~gateware.mac.path.TransmitPath`, all generated Verilog; the GTP and its clock buffers
  are the behavioural models of ``sim/hdl/``.
* Three oscillators (``board_clock.v``): the SFP's 125 MHz reference (``SFPREF``), the core's
  125 MHz (``CORE``: ``sync`` and ``gmii_tx``) and the partner's (``PARTNER``), each off by the
  parts per billion its plusargs say.
* The partner's transceiver: a second ``GTPA1_DUAL`` model on the partner's clock, its serial
  output looped to the board's input and back. The partner itself is Python
  (:class:`sim.models.pcs_partner.Partner`): it gives a 10-bit word each cycle of
  ``partner_tx_clk`` and takes one each cycle of ``partner_rx_clk`` (its recovered clock).
"""

from types import SimpleNamespace

from amaranth import Cat, ClockDomain, ClockSignal, Const, Instance, Module, ResetSignal, Signal
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from gateware.mac.gmii_rx import counters_layout
from gateware.mac.path import ReceivePath, TransmitPath
from gateware.platform.pins import SfpPhy
from sim.harness.paths import ROOT
from sim.rigs.fast_system_rig import power_on_reset
from sim.rigs.tiled_rig import VERILATOR_TIMING

__all__ = ["SfpLink", "TOPLEVEL", "SOURCES", "BUILD_ARGS", "LINK_TIMER", "MAX_FRAME", "plusargs"]

TOPLEVEL = "sfp_link"
SOURCES = [ROOT / "sim" / "hdl" / name for name in ("gtpa1_dual.v", "gtp_clock_buffers.v", "board_clock.v")]
#: The partner's transceiver and the clock buffers leave the ports their models ignore open.
BUILD_ARGS = [*VERILATOR_TIMING, "-Wno-PINMISSING"]
#: Auto-negotiation's link timer in simulation (cycles): short, so that a negotiation takes
#: microseconds; the partner's model uses the same.
LINK_TIMER = 400
#: The longest frame, FCS included (no jumbo frames on this link).
MAX_FRAME = 1518
#: Nominal period of the three oscillators (fs): 125 MHz.
PERIOD_FS = 8_000_000


def plusargs(*, sfp_ppm=0.0, core_ppm=0.0, partner_ppm=0.0):
    """The oscillators' plusargs for frequency errors in ppm (positive: fast)."""
    out = []
    for name, ppm in (("SFPREF", sfp_ppm), ("CORE", core_ppm), ("PARTNER", partner_ppm)):
        out += [f"+{name}_PERIOD_FS={PERIOD_FS}", f"+{name}_PPB={round(ppm * 1000)}"]
    return out


class SfpLink(wiring.Component):
    """The board's MAC and SFP PHY, the partner's transceiver, the oscillators.

    Members
    -------
    s_axis_tdata, s_axis_tvalid, s_axis_tlast : In; s_axis_tready : Out
        Frames to send (destination MAC to payload), in ``sync`` (``core_clk``).
    m_axis_tdata, m_axis_tvalid, m_axis_tlast, m_axis_tuser : Out; m_axis_tready : In
        Frames received (destination MAC to payload), in ``sync``; ``m_axis_tuser`` on the last
        byte marks a bad frame.
    counters : Out(counters_layout(32)), rx_dropped, tx_underruns : Out(32)
        The MAC's, in ``sync``.
    sync_status, an_complete, xmit, losses, slips, restarts : Out
        The PCS's (on the recovered clock; read them as levels).
    partner_tx : In(10)
        The partner's word to send, first bit in bit 0, on ``partner_tx_clk``.
    partner_rx : Out(10)
        The partner's received word, first bit in bit 0, on ``partner_rx_clk``.
    core_clk, partner_tx_clk, partner_rx_clk : Out(1)
    core_clk_n : Out(1)
        ``core_clk`` inverted: a clock generated inside the design shows the testbench its
        registers' values after its edge, so the testbench's stream drivers run half a cycle
        away from it.
    """

    def __init__(self):
        layout = counters_layout(32)
        super().__init__({
            "s_axis_tdata": In(8), "s_axis_tvalid": In(1), "s_axis_tlast": In(1), "s_axis_tready": Out(1),
            "m_axis_tdata": Out(8), "m_axis_tvalid": Out(1), "m_axis_tlast": Out(1), "m_axis_tuser": Out(1),
            "m_axis_tready": In(1),
            "counters": Out(layout), "rx_dropped": Out(32), "tx_underruns": Out(32),
            "sync_status": Out(1), "an_complete": Out(1), "xmit": Out(2),
            "losses": Out(16), "slips": Out(16), "restarts": Out(16),
            "partner_tx": In(10), "partner_rx": Out(10),
            "core_clk": Out(1), "core_clk_n": Out(1), "partner_tx_clk": Out(1), "partner_rx_clk": Out(1),
        })

    def elaborate(self, platform):
        m = Module()
        ref, core, partner = Signal(), Signal(), Signal()
        for name, clk in (("SFPREF", ref), ("CORE", core), ("PARTNER", partner)):
            m.submodules[f"{name.lower()}_oscillator"] = Instance("board_clock", p_PLUSARG=name, i_trim=Const(0, 16),
                                                                  o_clk=clk)
        power_on_reset(m, "sync", core)
        m.domains += ClockDomain("gmii_tx")
        m.d.comb += [ClockSignal("gmii_tx").eq(core), self.core_clk.eq(core), self.core_clk_n.eq(~core)]
        m.domains += ClockDomain("gmii_rx")

        # the line: the board's pins and the partner's
        txp, txn, rxp, rxn = Signal(), Signal(), Signal(), Signal()
        pads = SimpleNamespace(tx=SimpleNamespace(p=txp, n=txn), rx=SimpleNamespace(p=rxp, n=rxn))
        refclk = SimpleNamespace(p=ref, n=~ref)
        m.submodules.phy = phy = SfpPhy(pads, refclk, link_timer=LINK_TIMER)
        m.d.comb += [phy.reset.eq(ResetSignal("sync")), phy.locked.eq(1)]
        m.submodules.receive = receive = ReceivePath(max_frame=MAX_FRAME, depth=4096)
        m.submodules.transmit = transmit = TransmitPath(depth=2048)
        m.d.comb += [receive.gmii.eq(phy.rx), phy.tx.eq(transmit.gmii)]
        m.d.comb += [
            transmit.frames.payload.data.eq(self.s_axis_tdata), transmit.frames.payload.last.eq(self.s_axis_tlast),
            transmit.frames.valid.eq(self.s_axis_tvalid), self.s_axis_tready.eq(transmit.frames.ready),
            self.m_axis_tdata.eq(receive.frames.payload.data), self.m_axis_tlast.eq(receive.frames.payload.last),
            self.m_axis_tuser.eq(receive.frames.payload.user), self.m_axis_tvalid.eq(receive.frames.valid),
            receive.frames.ready.eq(self.m_axis_tready),
            self.counters.eq(receive.counters), self.rx_dropped.eq(receive.dropped),
            self.tx_underruns.eq(transmit.underruns),
            *[getattr(self, name).eq(getattr(phy, name)) for name in ("sync_status", "losses", "slips", "restarts")],
            self.an_complete.eq(phy.mr_an_complete), self.xmit.eq(phy.xmit),
        ]

        # the partner's transceiver: the same model, lane 0, on the partner's clock
        gtpclkout, rxdata, rxcharisk, rxdisperr = Signal(2), Signal(32), Signal(4), Signal(4)
        m.submodules.partner_gtp = Instance(
            "GTPA1_DUAL", p_SIM_RX_OFFSET=7,
            i_CLK00=partner, i_GTPRESET0=0, i_TXUSRCLK0=partner, i_TXUSRCLK20=partner,
            i_TXDATA0=self.partner_tx[:8], i_TXCHARDISPVAL0=self.partner_tx[8], i_TXCHARDISPMODE0=self.partner_tx[9],
            o_TXP0=rxp, o_TXN0=rxn, i_RXP0=txp, i_RXN0=txn,
            o_GTPCLKOUT0=gtpclkout, i_RXUSRCLK0=gtpclkout[1], i_RXUSRCLK20=gtpclkout[1],
            o_RXDATA0=rxdata, o_RXCHARISK0=rxcharisk, o_RXDISPERR0=rxdisperr)
        m.d.comb += [self.partner_rx.eq(Cat(rxdata[:8], rxcharisk[0], rxdisperr[0])),
                     self.partner_tx_clk.eq(partner), self.partner_rx_clk.eq(gtpclkout[1])]
        return m

