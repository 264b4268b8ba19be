"""The projector on the Spartan-6 board: the core, its clocks, pins and memory controller.

Everything vendor-specific lives here and in :mod:`gateware.platform`; the core
(:class:`gateware.top.system.Projector`) simulates without any of it.
"""

from amaranth import ClockDomain, DomainRenamer, Elaboratable, Module
from amaranth.lib import io, wiring

from gateware.platform.clocks import DCLK_HZ, Spartan6Clocks
from gateware.platform.mcb_instance import McbInstance
from gateware.platform.pins import Dlpc410Pins, TriggerPins, VcxoDacPins
from gateware.registers import Registers
from gateware.sync.trim_dac import TrimDac
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


def core(dmd, dclk_hz=DCLK_HZ):
    """The projector's core as the board builds it: disarmed, with power-up sequencer registers
    of the shortest legal 8-bit global schedule at the facts' timing and DCLK ``dclk_hz``, early
    triggers held (the host replaces them with sequencer records, and arms the triggers)."""
    plan = schedule.plan(dmd, dclk_hz, depth=8, trigger_hold=True)
    return Projector(dmd, sync_hz=Spartan6Clocks.frequencies(dclk_hz)["sync"], beats=plan.params.beats,
                     regs=Registers.const(plan.params.registers(dmd)), armed=False, sync_pad_sampled=True,
                     **ADDRESSES)


class PlatformTop(Elaboratable):
    """The whole projector for a board of :data:`gateware.platform.BOARDS`: its oscillator and
    reset (``default_clk``, ``default_rst``), its Ethernet PHY (``ethernet``), its DLPC410
    adapter and its memory (``memory``), as the platform class names them.

    Parameters
    ----------
    dmd : str
        DMD name in :data:`spec.facts.DMDS`; the board's adapter must carry its buses (the
        Atlys two, the SVEC four).
    dclk_hz : float
        DCLK: 400 MHz (the default: two beats a ``dmd`` cycle through OSERDES2s) or 200 MHz.
    """

    def __init__(self, dmd="dlp7000", dclk_hz=DCLK_HZ):
        self._dmd = DMDS[dmd]
        self._dclk_hz = dclk_hz

    def elaborate(self, platform):
        dmd = self._dmd
        # a board whose adapter cannot carry this DMD is refused before anything is built
        Dlpc410Pins.check(platform, dmd.buses)
        m = Module()

        # ---- Clocks: the board oscillator through the PLL; RX_CLK from the PHY ------------------
        clk = platform.request(platform.default_clk, dir="-")
        rst = platform.request(platform.default_rst, dir="-")
        m.submodules.clk_buf = clk_buf = io.Buffer("i", clk)
        m.submodules.rst_buf = rst_buf = io.Buffer("i", rst)
        m.domains += [*Spartan6Clocks.domains(self._dclk_hz), ClockDomain("gmii_rx")]
        m.submodules.clocks = clocks = Spartan6Clocks(clk_buf.i, rst_buf.i, self._dclk_hz,
                                                      platform.default_clk_frequency)

        # ---- Pins ---------------------------------------------------------------------------
        m.submodules.gmii = gmii = platform.ethernet(clocks.locked)
        beats = schedule.beats_at(self._dclk_hz)
        m.submodules.dlpc410 = dlpc = Dlpc410Pins(dmd.buses, beats, clocks.io)
        m.submodules.trigger = trigger = TriggerPins()

        # ---- The core ------------------------------------------------------------------------
        m.submodules.core = projector = core(dmd, self._dclk_hz)
        gmii.connect(m, projector)
        wiring.connect(m, projector.dlpc, dlpc.bus)
        m.d.comb += [
            projector.trigger_in.eq(trigger.trigger),
            projector.sync_in.eq(trigger.sync_in),
            projector.sync_in_fall.eq(trigger.sync_in_fall),
            trigger.sync.eq(projector.sync_out),
            trigger.camera.eq(projector.camera_out),
            trigger.gate.eq(projector.gate_out),
            trigger.ready.eq(projector.ready_out),
        ]
        # ---- The VCXO's DAC, on a board that carries one: the clock loop pulls the oscillator --
        if platform.vcxo_dac:
            m.submodules.trim_dac = dac = DomainRenamer("dmd")(TrimDac(schedule.FABRIC_HZ))
            m.submodules.vcxo_dac = dac_pins = VcxoDacPins()
            m.d.comb += [dac.trim.eq(projector.vcxo_trim),
                         *[getattr(dac_pins, name).eq(getattr(dac, name)) for name in VcxoDacPins.LINES]]
        # ---- DDR2 or DDR3 through the memory controller ---------------------------------------
        m.submodules.mcb = mcb = McbInstance(memory=platform.memory, port0_domain="sync", port1_domain="dmd")
        wiring.connect(m, projector.mcb_write, mcb.port0)
        wiring.connect(m, projector.mcb_read, mcb.port1)
        m.d.comb += [mcb.sys_clk.eq(clk_buf.i), mcb.sys_rst.eq(rst_buf.i)]
        return m
