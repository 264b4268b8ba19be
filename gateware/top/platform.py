"""The projector on the Spartan-6 board: the core, its clocks, pins and memory controller.

Everything vendor-specific lives here and in :mod:`gateware.platform`; the core
(:class:`gateware.top.system.Projector`) simulates without any of it.
"""

from amaranth import ClockDomain, Elaboratable, Module
from amaranth.lib import io, wiring

from gateware.platform.clocks import Spartan6Clocks
from gateware.platform.mcb_instance import McbInstance
from gateware.platform.pins import Dlpc410Pins, GmiiPins, TriggerPins
from gateware.registers import Registers
from spec import schedule
from spec.facts import DMDS

from .system import Projector

__all__ = ["PlatformTop", "core", "ADDRESSES", "UCF_EXTRA"]

#: Network addresses at power-up; a control record changes them at run time.
ADDRESSES = dict(mac=0x02_44_4D_00_00_01, ip=0xC0_A8_01_0A, port=5000)

#: Timing ignores on the first stage of every synchroniser (FFSynchronizer, ResetSynchronizer,
#: AsyncFIFO pointers: Amaranth names those flip-flops ``stage0``), and the PHY's receive clock.
UCF_EXTRA = """
INST "*stage0*" TNM = "cdc_first_stages";
TIMESPEC "TS_cdc_first_stages" = TO "cdc_first_stages" TIG;
"""


def core(dmd, frequencies):
    """The projector's core as the board builds it: disarmed, with power-up sequencer registers
    of the shortest legal 8-bit global schedule at the facts' timing (the host replaces them with
    sequencer records, and arms the triggers). ``frequencies``: ``{domain: Hz}``."""
    plan = schedule.plan(dmd, frequencies["dmd"], depth=8)
    return Projector(dmd, sync_hz=frequencies["sync"], regs=Registers.const(plan.params.registers(dmd)),
                     armed=False, **ADDRESSES)


class PlatformTop(Elaboratable):
    """The whole projector for :data:`gateware.platform.Board`.

    Parameters
    ----------
    dmd : str
        DMD name in :data:`spec.facts.DMDS`.
    """

    def __init__(self, dmd="dlp7000"):
        self._dmd = DMDS[dmd]

    def elaborate(self, platform):
        m = Module()
        dmd = self._dmd

        # ---- Clocks: the board oscillator through the PLL; RX_CLK from the PHY ------------------
        clk100 = platform.request("clk100", dir="-")
        rst = platform.request("rst", dir="-")
        m.submodules.clk_buf = clk_buf = io.Buffer("i", clk100)
        m.submodules.rst_buf = rst_buf = io.Buffer("i", rst)
        m.domains += [*Spartan6Clocks.domains(), ClockDomain("gmii_rx")]
        m.submodules.clocks = clocks = Spartan6Clocks(clk_buf.i, rst_buf.i)

        # ---- Pins ---------------------------------------------------------------------------
        m.submodules.gmii = gmii = GmiiPins(clocks.locked)
        m.submodules.dlpc410 = dlpc = Dlpc410Pins(dmd.buses)
        m.submodules.trigger = trigger = TriggerPins()

        # ---- The core ------------------------------------------------------------------------
        m.submodules.core = projector = core(dmd, clocks.frequencies())
        m.d.comb += [projector.gmii_rx.eq(gmii.rx), gmii.tx.eq(projector.gmii_tx)]
        m.d.comb += [
            gmii.phy_reset_n.eq(projector.phy_reset_n), gmii.mdc.eq(projector.mdc),
            gmii.mdio_o.eq(projector.mdio_o), gmii.mdio_oe.eq(projector.mdio_oe), projector.mdio_i.eq(gmii.mdio_i),
        ]
        wiring.connect(m, projector.dlpc, dlpc.bus)
        m.d.comb += [
            projector.trigger_in.eq(trigger.trigger),
            trigger.sync.eq(projector.sync_out),
            trigger.camera.eq(projector.camera_out),
        ]
        # ---- DDR2 through the memory controller ----------------------------------------------
        m.submodules.mcb = mcb = McbInstance(port0_domain="sync", port1_domain="dmd")
        wiring.connect(m, projector.mcb_write, mcb.port0)
        wiring.connect(m, projector.mcb_read, mcb.port1)
        m.d.comb += [mcb.sys_clk.eq(clk_buf.i), mcb.sys_rst.eq(rst_buf.i)]
        return m
