"""CERN's SVEC (Simple VME FMC Carrier) as the DLP9500 projector's board.

The SVEC's application FPGA is an XC6SLX150T-3FGG900 with two FMC LPC slots, each wired with
LA00..LA33 and CLK0/CLK1_M2C: 2 x 36 = 72 pairs, exactly the 72 LVDS pairs of a four-bus DLPC410
link (DIN_A..D, DCLK_A..D, DVALID_A..D). Its VME P2 connector's 20 user pairs (40 pins at 2.5 V)
take the 35 single-ended control and status lines and the five trigger lines. DDR3 hangs on the
memory controllers of banks 4 and 5; Ethernet reaches it only through its SFP cage (GTP).

Pin locations are the SVEC's, from the SVEC project's HDL repository (ohwr.org/project/svec):
the FMC slots and the P2 pins from the application FPGA's constraints of the first board
revision (``svec_v0_afpga.ucf``), the clock, reset, DDR3 (bank 4), SFP and the VCXO's DAC from
the constraint files the current reference design builds with (``svec_base_common.ucf``,
``svec_base_ddr4.ucf``, ``svec_base_wr.ucf``). Which signal of the DLPC410 goes on which of those pins is the adapter's
assumption (:mod:`.dlpc410_adapter`, ``constraints/README.md``). Nothing here has been through
ISE.
"""

from amaranth.build import Attrs, Clock, Connector, DiffPairs, Pins, PinsN, Resource, Subsignal
from amaranth.vendor import XilinxPlatform

from .dlpc410_adapter import CONTROL_LINES, FMC_PAIRS, LVCMOS25, LVCMOS33, dlpc410_fmc_resources, trigger_resources
from .mcb_instance import Memory
from .pins import SfpGmiiPins

__all__ = ["SvecPlatform", "SvecProjectorPlatform", "SVEC_DDR3", "P2_PINS"]

#: FMC slot pins (``svec_v0_afpga.ucf``, "FMC slot 1" and "FMC slot 2": connectors ``fmc`` 0 and 1
#: here, ``fmc0`` and ``fmc1`` in the current constraint files) in the order of
#: :data:`~.dlpc410_adapter.FMC_PAIRS` (LA00..LA33, CLK0_M2C, CLK1_M2C): the P pins, the N pins.
_FMC_PINS = [
    ("C16 H21 J22 E25 D24 M19 B25 G22 F23 M20 L21 G20 F21 G18 F17 H16 F19 "
     "B15 J14 G14 F15 G12 F13 M15 G10 F11 L14 M13 L12 F9 J13 L11 H11 J12 H15 E16",
     "A16 G21 H22 D25 C24 L19 A25 F22 E23 L20 K21 F20 E21 F18 E17 G16 E19 "
     "A15 H14 F14 E15 F12 E13 K15 F10 E11 K14 L13 K12 E9 H13 K11 G11 H12 G15 D16"),
    ("AJ17 AG8 AC11 AE13 AJ15 AE11 AD10 AD12 AB12 W14 Y14 Y16 AE15 AC15 Y15 Y17 AB14 "
     "AC16 AE21 AE23 AE19 AD22 AE24 AF25 AB21 AB17 AC19 AB20 AA22 AC24 W20 Y21 W19 AA19 AF16 AH16",
     "AK17 AH8 AD11 AF13 AK15 AF11 AE10 AE12 AC12 Y13 AA14 AB16 AF15 AD15 AA15 AA17 AC14 "
     "AD16 AF21 AF23 AF19 AE22 AF24 AG25 AC21 AD17 AD19 AC20 AC22 AD24 Y20 AA21 Y19 AB19 AG16 AK16"),
]

#: VME P2 user pairs 0..19 (``svec_v0_afpga.ucf``, "VME P2": ``p2_data_p_b``, ``p2_data_n_b``).
_P2_PINS = ("AA11 W12 AB10 AH7 F6 H7 D8 J8 L17 M10 AF7 AG6 AD8 AE9 D6 E7 F8 H17 K10 B7",
            "AB11 Y12 AB9 AK7 E6 G7 C8 H8 K17 L10 AG7 AH6 AE8 AF9 C6 D7 E8 G17 J10 A7")

#: The "vme_p2" connector's pins as this tree numbers them: 2k+1 is pair k's P pin, 2k+2 its N.
P2_PINS = [str(pin) for pin in range(1, 41)]


def _fmc_connector(slot):
    p, n = (pins.split() for pins in _FMC_PINS[slot])
    return Connector("fmc", slot, {name: pin for names, pins in zip(FMC_PAIRS, zip(p, n, strict=True), strict=True)
                                   for name, pin in zip(names, pins, strict=True)})


def _p2_connector():
    p, n = (pins.split() for pins in _P2_PINS)
    return Connector("vme_p2", 0, {str(2 * k + 1 + side): pair[side]
                                   for k, pair in enumerate(zip(p, n, strict=True)) for side in (0, 1)})


#: The DDR3 on bank 4 (``svec_base_ddr4.ucf``: 16 data bits, 14 row address bits, RZQ on L7),
#: named as amaranth-boards' Atlys ``ddr2`` so that the controller's pin table is shared: ``dm``
#: and ``dqs`` list the upper byte's first.
_DDR3 = Resource(
    "ddr3", 0,
    Subsignal("clk", DiffPairs("E3", "E1", dir="o"), Attrs(IOSTANDARD="DIFF_SSTL15_II")),
    Subsignal("clk_en", Pins("C4", dir="o")),
    Subsignal("we", PinsN("F4", dir="o")),
    Subsignal("ras", PinsN("C1", dir="o")),
    Subsignal("cas", PinsN("B1", dir="o")),
    Subsignal("reset", PinsN("G5", dir="o")),
    Subsignal("a", Pins("D4 D3 A3 E5 C5 F2 F1 B3 B2 A2 D5 G4 A4 B5", dir="o")),
    Subsignal("ba", Pins("D2 D1 F3", dir="o")),
    Subsignal("dqs", DiffPairs("K2 J5", "K1 J4", dir="io"), Attrs(IOSTANDARD="DIFF_SSTL15_II", IN_TERM="NONE")),
    Subsignal("dq", Pins("H4 H3 J3 J1 G3 G1 H2 H1 M4 M3 L5 L4 L3 L1 M2 M1", dir="io"), Attrs(IN_TERM="NONE")),
    Subsignal("dm", Pins("K4 K3", dir="o")),
    Subsignal("odt", Pins("E4", dir="o")),
    Attrs(IOSTANDARD="SSTL15_II"),
)

#: The DDR3 on bank 4 behind MCB4, as a generator project for it would name the wrapper (an
#: assumption: no such project is in this tree, see ``constraints/README.md``).
SVEC_DDR3 = Memory("svec_ddr3", 4, "ddr3", 14,
                   Resource("ddr3_calibration", 0, Subsignal("rzq", Pins("L7", dir="io")),
                            Attrs(IOSTANDARD="SSTL15_II")),
                   ddr3=True)


class SvecPlatform(XilinxPlatform):
    """The SVEC's application FPGA: the resources the projector uses, and the FMC and P2
    connectors.

    The 125 MHz PLL reference (``clk125``) and the reset (``rst``, active low) are the reference
    design's; the GTP reference clock and the SFP cage's lines are those of its White Rabbit
    constraints.
    """

    device = "xc6slx150t"
    package = "fgg900"
    speed = "3"

    default_clk = "clk125"
    default_rst = "rst"
    resources = [
        Resource("clk125", 0, DiffPairs("AB28", "AB30", dir="i"), Clock(125e6), Attrs(IOSTANDARD="LVDS_25")),
        Resource("rst", 0, PinsN("AD28", dir="i"), LVCMOS33),
        _DDR3,
        Resource("sfp", 0,
                 Subsignal("tx", DiffPairs("B23", "A23", dir="o")),
                 Subsignal("rx", DiffPairs("D22", "C22", dir="i")),
                 Subsignal("tx_disable", Pins("AA25", dir="o"), LVCMOS33),
                 Subsignal("los", Pins("W25", dir="i"), LVCMOS33)),
        Resource("sfp_refclk", 0, DiffPairs("B19", "A19", dir="i")),
        # the AD5662 that sets the 25 MHz VCXO the 125 MHz reference is locked to
        # (``svec_base_wr.ucf``: pll25dac_sclk_o, pll25dac_din_o, pll25dac_sync_n_o)
        Resource("vcxo_dac", 0,
                 Subsignal("sclk", Pins("N27", dir="o")), Subsignal("din", Pins("P25", dir="o")),
                 Subsignal("sync_n", Pins("P26", dir="o")), LVCMOS33),
    ]
    connectors = [_fmc_connector(0), _fmc_connector(1), _p2_connector()]


_CONTROL_PINS = sum(width for _name, width, _dir in CONTROL_LINES)


class SvecProjectorPlatform(SvecPlatform):
    """The SVEC with the two-FMC DLPC410 adapter: the four buses on the FMC slots, the control
    and status lines on P2 pins 1..35, the trigger lines on P2 pins 36..40 (all at 2.5 V: the
    adapter's level shifters take the sensor's 5 V trigger)."""

    resources = SvecPlatform.resources + dlpc410_fmc_resources(("vme_p2", 0), P2_PINS[:_CONTROL_PINS]) \
        + trigger_resources(("vme_p2", 0), P2_PINS[_CONTROL_PINS:], LVCMOS25)
    dlpc410_complete = True
    dlpc410_buses = 4
    #: no light gate pin: every pin of P2 this tree places is taken (constraints/README.md)
    light_gate = False
    #: the memory the store uses and its controller
    memory = SVEC_DDR3
    #: the Ethernet PHY: the SFP cage through a 1000BASE-X PCS inside the FPGA
    ethernet = SfpGmiiPins
    #: the clock loop pulls the 25 MHz VCXO behind ``clk125`` through its DAC (``vcxo_dac``)
    vcxo_dac = True
