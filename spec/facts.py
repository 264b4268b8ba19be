"""Facts about the TI DLPC410 controller and its DMDs, in one table each, with their sources.

Every number the gateware or a model takes from a TI document lives here, as a parameter with
its source named; nothing else in the tree writes such a number down. Where a value is uncertain
the entry says so and callers take it as a run-time or build-time parameter.

Sources
-------
802.3       IEEE 802.3 clause 22 (MDIO frame, MDC <= 2.5 MHz, basic registers)
88E1111     Marvell 88E1111 PHY datasheet (register 17 "PHY specific status", reset timing)
Atlys       Digilent Atlys reference manual (PHY strapping)
DLPC410     DLPC410 datasheet (DLPS024), row addressing and command tables
DLPU045A    DLPC410 programming note: DCLK, even idle cycles
DLPA008B    DLPC410 application note: reset, settle, clears, phased operation
DLPU040C    DLPC410 user guide, table 1-1 (binary pattern rates)
DLP7000     DLP7000 datasheet (timing 7.12, initialisation 8.3)
DLPC910     sister part's datasheet (same interface family)
refHDL      TI's applications-FPGA reference HDL as quoted in public repositories
forum       TI E2E forum answers (quoting the datasheet); Mathews et al., IEEE QCE 2022 (measured)
DLPU133     DLPC964 applications FPGA user guide (loading into settling mirrors)
four-DMD    the tiled four-DLP9500 projector paper (2026), eq. 6-7 (450.6 Hz 8-bit, runs at 400 Hz)
DS162       Xilinx Spartan-6 FPGA data sheet: DC and switching characteristics (PLL; CLB switching
            characteristics, -3 speed grade)
assumption  a planning figure, no document behind it: said so in the entry
AD5662      Analog Devices AD5662 16-bit nanoDAC data sheet (serial interface timing)
E2E-594673  TI E2E forum, "DLP7000: how to achieve maxim pattern rate for DLP7000 8bit greyscale"
            (thread 594673): 43.22 us a global-reset bit-plane, 8-bit with modulated light
DLP7000-p1  DLP7000 datasheet, page 1: "> 1900 Hz (8-bit gray)"
OE-32-10373 Optics Express 32(6):10373 (2024): two DMDs in weighted light, 8-bit
PH-11-793   Photonics 11(9):793 (2024), doi:10.3390/photonics11090793: two DMDs (one modulates the
            source), 12-bit
OLE-108171  Optics and Lasers in Engineering 108171 (2024), doi:10.1016/j.optlaseng.2024.108171:
            two parallel DMDs lit at different intensities, 16-bit
SVEC        CERN SVEC carrier: DDR3 on bank 4 (svec_base_ddr4.ucf: 14 row address lines, 3 bank,
            16 data bits; constraints/README.md)
"""

import enum
from dataclasses import dataclass

__all__ = ["Fact", "TIMING", "LIGHT",
           "SettleReading", "SETTLE_READINGS", "PHY", "SPARTAN6", "VCXO_DAC", "DmdType", "DMDS",
           "SPARTAN6_PATH", "RowMode", "BlockMode", "WEIGHTED",
           "TEST_DMD", "TEST_DMD4",
           "TEST_DMD_400", "TEST_DMD4_400", "MEMORY", "ANCHORS"]


@dataclass(frozen=True)
class Fact:
    value: float
    unit: str
    source: str
    confidence: str = "high"
    note: str = ""


#: Timing rules. Durations in seconds; the gateware takes them as cycle counts at run time.
TIMING = {
    "t_rst_active": Fact(4.54e-6, "s", "forum (measured 908 cycles at 200 MHz)", "medium",
                         "RST_ACTIVE high after a mirror clocking pulse; no new pulse before it falls"),
    "t_settle": Fact(8e-6, "s", "forum; DLPA008B 4.1", "medium",
                     "after RST_ACTIVE falls, a pulsed block's memory must not change for this long"),
    "t_pulse_to_mirror": Fact(4.5e-6, "s", "forum (TI E2E DLP9500 thread 1075252)", "medium",
                              "from the start of a mirror clocking pulse (reset) to the start of the "
                              "mirrors' motion; fixed by the physics, whatever the number of blocks"),
    "t_crossover": Fact(4e-6, "s", "DLP7000 7.12", "high", "mirror crossover time"),
    "t_switch": Fact(12.5e-6, "s", "DLP7000 7.12", "high", "typical mirror switching time"),
    "t_init": Fact(220e-3, "s", "DLP7000 8.3", "medium", "INIT_ACTIVE high after ARSTZ"),
    "init_to_dvalid_clocks": Fact(64, "DCLK", "DLPC910", "medium",
                                  "first DVALID at least this many clocks after INIT_ACTIVE falls"),
    "global_overhead": Fact(13.5e-6, "s", "DLPU040C table 1-1, derived", "medium",
                            "per-frame overhead of global-reset binary patterns"),
    "training_pattern": Fact(0b0100, "bits per 4 edges", "DLPC410 datasheet (training pattern)", "high",
                             "during initialisation every data pin and DVALID repeat 0100 over four "
                             "DDR edges (two DCLK cycles; the DLPC410 aligns to any phase): rising 0, "
                             "falling 1, rising 0, falling 0. Written MSB first: edge 0 is bit 3"),
    "t_pwr_float": Fact(300e-6, "s", "DLPC410", "medium", "mirror parking after PWR_FLOAT"),
    "t_watchdog": Fact(10.0, "s", "DLPC410", "medium", "WDT_ENBLZ low: forced reset if none issued"),
    "dclk_min": Fact(200e6, "Hz", "DLP7000 table 8-2", "high"),
    "dclk_max": Fact(400e6, "Hz", "DLP7000 table 8-2; DLPU045A (new PROM: 400 MHz only)", "high"),
}


#: The modulated light source the sequencer's gate pin switches (an IR LED array or a laser). Its
#: edges are linear ramps of these lengths in the camera model; equal rise and fall make a pulse's
#: light integrate to its gate time exactly.
LIGHT = {
    "t_rise": Fact(50e-9, "s", "assumption (planning figure, no document)", "assumption",
                   "gate on to full light: a driven IR LED array or a laser diode driver; a slower "
                   "source wants the on-times trimmed"),
    "t_fall": Fact(50e-9, "s", "assumption (planning figure, no document)", "assumption",
                   "gate off to no light, as the rise"),
}

@dataclass(frozen=True)
class SettleReading:
    """What the mirrors' settle time (``TIMING["t_settle"]``) forbids.

    ``frozen``: a pulsed block's memory must not change until ``t_settle`` after RST_ACTIVE falls.
    Otherwise (``flip``) it may change as soon as RST_ACTIVE falls, and only the block's next pulse
    must wait: no sooner than ``t_settle`` after its last one.
    """
    name: str
    frozen: bool
    source: str
    note: str

    @property
    def flip(self):
        return not self.frozen


#: Readings of the settle time. TI's is the default and the only one the rule model takes unless
#: told; the four-DMD paper's is kept to compare like with like, never as a default.
SETTLE_READINGS = {
    "ti": SettleReading("ti", True, "DLPU133; DLPA008B 4.1",
                        "loading data into mirrors that are settling can put the DMD in an unknown state"),
    "paper": SettleReading("paper", False, "four-DMD eq. 6-7",
                           "the settle forbids only a new flip: memory loads as soon as RST_ACTIVE falls, "
                           "and a block's pulses come at least t_settle apart (the equations' 8 us unit)"),
}


@dataclass(frozen=True)
class DmdType:
    """A DMD as the DLPC410 addresses it.

    ``columns`` is the width sent on the bus (the DLP9500's 1920 columns are sent as 2048).
    """
    name: str
    columns: int
    rows: int
    visible_columns: int
    blocks: int
    rows_per_block: int
    buses: int
    bits_per_dclk: int
    dclk_per_row: int
    dmd_type_code: int | None
    clear_row_cycles: int
    source: str

    @property
    def words_per_row(self):
        """64-bit words in one row of one bit-plane."""
        return self.columns // 64

    @property
    def words_per_plane(self):
        return self.words_per_row * self.rows

    def block_of_row(self, row):
        return row // self.rows_per_block

    def __post_init__(self):
        assert self.columns % 64 == 0
        assert self.blocks * self.rows_per_block == self.rows


#: DMDs (DLPC410 datasheet row addressing; DMD_TYPE codes from refHDL; clear cost DLPA008B 4.2).
DMDS = {
    "dlp7000": DmdType("DLP7000 0.7in XGA", 1024, 768, 1024, 16, 48, 2, 64, 16, 0b0001, 1,
                       "DLPC410 row addressing; refHDL DMD_TYPE"),
    "dlp9500": DmdType("DLP9500 0.95in 1080p", 2048, 1080, 1920, 15, 72, 4, 128, 16, 0b0000, 3,
                       "DLPC410 row addressing; refHDL DMD_TYPE; 1080p clear = 1 + 2 no-op rows"),
    "dlp650lnir": DmdType("DLP650LNIR 0.65in WXGA", 1280, 800, 1280, 16, 50, 2, 32, 40, 0b0111, 1,
                          "DLPC410 row addressing; refHDL DMD_TYPE"),
}

#: A small DMD for fast tests: same rules, 128x96 in 4 blocks of 24 rows, XGA-style bus.
TEST_DMD = DmdType("test 128x96", 128, 96, 128, 4, 24, 2, 64, 2, None, 1, "test geometry")
DMDS["test"] = TEST_DMD
#: A small four-bus DMD: DLP9500-style bus (two words per DCLK on A-D) and clear (one row cycle
#: plus two no-op rows), 256x80 in 5 blocks of 16 rows (an odd block count, as the DLP9500's 15).
TEST_DMD4 = DmdType("test four-bus 256x80", 256, 80, 256, 5, 16, 4, 128, 2, None, 3,
                    "test geometry, DLP9500-style")
DMDS["test4"] = TEST_DMD4
#: Small DMDs for DCLK 400 MHz tests, where a row cycle is half its DCLK cycles: four DCLK per
#: row (two ``dmd`` cycles), on two buses (256x96 in 4 blocks) and four (512x80 in 5 blocks).
TEST_DMD_400 = DmdType("test 256x96", 256, 96, 256, 4, 24, 2, 64, 4, None, 1, "test geometry, four DCLK per row")
DMDS["test_400"] = TEST_DMD_400
TEST_DMD4_400 = DmdType("test four-bus 512x80", 512, 80, 512, 5, 16, 4, 128, 4, None, 3,
                        "test geometry, DLP9500-style, four DCLK per row")
DMDS["test4_400"] = TEST_DMD4_400


class RowMode(enum.IntEnum):
    """ROWMD(1:0) (DLPC410 for 00 and 10; DLPC910 and refHDL for 01 and 11)."""
    NOOP = 0b00
    NEXT = 0b01       # advance the row pointer and write (decrement with NS_FLIP)
    ADDRESSED = 0b10  # write at ROWAD
    FIRST = 0b11      # pointer to row 0 and write there


class BlockMode(enum.IntEnum):
    """BLKMD(1:0) (refHDL; confidence medium). """
    NOOP = 0b00
    CLEAR = 0b01      # clear block BLKAD
    RESET = 0b10      # mirror clocking pulse of block BLKAD
    MULTI = 0b11      # dual (RST2BLKZ=0), quad (RST2BLKZ=1, BLKAD=0qq0) or global (BLKAD=10xx)


#: The frame store's memory: the Atlys's DDR2.
MEMORY = {
    "bytes": Fact(128 * 2**20, "B", "Micron MT47H64M16 (64 Mi x 16 bit); Digilent Atlys reference manual", "high",
                  "the one DDR2 part on the board"),
    "svec_bank4_bytes": Fact(256 * 2**20, "B", "SVEC (14 row address lines, 8 banks, x16: a 2 Gb x16 part)",
                             "medium", "the DDR3 on bank 4; the store sizes its slots by ``bytes`` and uses half"),
}



#: Frame rates others reached or TI states past one DMD's PWM, to set the bounds beside.
ANCHORS = {
    "gated_gray8_dlp7000_limit": Fact(2.89e3, "Hz", "E2E-594673", "high",
                                      "global reset at its fastest, 8 x 43.22 us, the source gated in each plane"),
    "gated_gray8_dlp7000": Fact(1.9e3, "Hz", "DLP7000-p1; E2E-594673", "high",
                                "TI's 8-bit rate with a modulated source"),
    "dual_gray8": Fact(1300, "Hz", "OE-32-10373", "medium", "two DMDs in weighted light, 8-bit (their DMD)"),
    "dimmed_gray12": Fact(1611, "Hz", "PH-11-793", "medium",
                          "a DMD modulating the source before an image DMD, 12-bit (their DMD)"),
    "dual_gray16": Fact(220, "Hz", "OLE-108171", "medium",
                        "two parallel DMDs lit at different intensities, quaternary PWM, 16-bit (their DMD)"),
}


def frames_held(rows, columns):
    """Whole 8-plane frames of ``rows`` x ``columns`` (a multiple of 64) the memory holds: the
    DLP7000's 170, the DLP9500's 60 in 128 MiB."""
    return int(MEMORY["bytes"].value) // (rows * columns)     # 8 planes of a bit a pixel


#: The Spartan-6 PLL, as the clock plans (:mod:`gateware.platform.clocks`) need it.
SPARTAN6 = {
    "pll_pfd_min": Fact(19e6, "Hz", "DS162 PLL specification (F_PFDMIN)", "medium",
                        "the phase detector's lowest input: the oscillator after the PLL's input divider"),
}


#: A register-to-register path on a -3 Spartan-6, as the path-delay estimate of the logic-depth
#: analysis (:func:`flow.timing.path_ns_estimate`) sums it. Seconds. The DS162 figures are its CLB
#: switching characteristics table's -3 column (ns, max), written down without a copy of the table
#: at hand to check them against: confidence low until they are read off DS162 again.
SPARTAN6_PATH = {
    "t_cko": Fact(0.39e-9, "s", "DS162 CLB switching characteristics table (TCKO, -3)", "low",
                  "flip-flop clock to AQ-DQ output; to check against the table"),
    "t_ilo": Fact(0.21e-9, "s", "DS162 CLB switching characteristics table (TILO, -3)", "low",
                  "a LUT's An-Dn address inputs to its output, one LUT level; to check against the table"),
    "t_as": Fact(0.33e-9, "s", "DS162 CLB switching characteristics table (TAS, -3)", "low",
                 "setup of an A-D flip-flop from its slice's An-Dn LUT inputs (through the LUT): the larger "
                 "of the two setup figures; to check against the table"),
    "t_dick": Fact(0.20e-9, "s", "DS162 CLB switching characteristics table (TDICK, -3)", "low",
                   "setup of an A-D flip-flop from the AX-DX bypass input; to check against the table"),
    "t_byp": Fact(0.08e-9, "s", "DS162 CLB switching characteristics table (TBYP, -3); ISE's speed "
                  "files if the table leaves it out", "low",
                  "a carry chain's CIN to COUT through one CARRY4, four bits; a quarter of it a bit"),
    "t_route_net": Fact(0.5e-9, "s", "assumption (planning figure, no document)", "assumption",
                        "routing allowance per net on a path: a few hundred ps is the usual planning "
                        "figure on Spartan-6, taken at its high end; a net of high fanout or one across "
                        "the die takes more, a net inside a slice (LUT to its own flip-flop) none"),
}


#: The AD5662 16-bit DAC that sets a VCXO's control voltage (the SVEC's White Rabbit VCXO DAC),
#: as the clock loop's writer (:mod:`gateware.sync.trim_dac`) needs it: 2.7-5.5 V timing.
VCXO_DAC = {
    "sclk_max": Fact(30e6, "Hz", "AD5662 timing characteristics (t1, SCLK cycle, 33 ns min)", "medium"),
    "t_sclk_half_min": Fact(13e-9, "s", "AD5662 timing characteristics (t2, t3: SCLK high, low)", "medium"),
    "t_sync_to_sclk_fall": Fact(13e-9, "s", "AD5662 timing characteristics (t4: SYNC to SCLK falling)",
                                "medium"),
    "t_data_setup": Fact(5e-9, "s", "AD5662 timing characteristics (t5)", "medium"),
    "t_data_hold": Fact(4.5e-9, "s", "AD5662 timing characteristics (t6)", "medium"),
    "t_sync_high_min": Fact(33e-9, "s", "AD5662 timing characteristics (t8: SYNC high between writes)",
                            "medium"),
    "frame_bits": Fact(24, "bits", "AD5662 input shift register", "high",
                       "DB23..DB18 don't care, DB17..DB16 power-down (00 normal), DB15..DB0 the code, MSB "
                       "first, each taken on SCLK's falling edge; the output updates on the 24th; SYNC "
                       "high before it abandons the write"),
    "code_bits": Fact(16, "bits", "AD5662", "high", "straight binary: mid-scale 0x8000"),
}


#: Two DMDs in weighted light (``host.weighted``): the attenuator's error the trim is shown against
#: (the published rates they are compared with are in :data:`ANCHORS`).
WEIGHTED = {
    "ratio_error": Fact(0.03, "", "assumption (a planning figure, no document)", "assumption",
                        "board B's light off 2**-k of board A's by this fraction before the trim: an "
                        "attenuator's tolerance of a few per cent"),
}


#: The Marvell 88E1111 PHY, as the management block (:mod:`gateware.mac.mdio`) needs it.
PHY = {
    "mdc_max": Fact(2.5e6, "Hz", "802.3 22.2.2.13", "high", "the 88E1111 accepts up to 8.3 MHz"),
    "reset_low": Fact(10e-3, "s", "88E1111 reset timing", "high", "RESETn low at least 10 ms"),
    "reset_to_mdio": Fact(5e-3, "s", "88E1111 reset timing", "medium", "wait after reset release"),
    "phy_address": Fact(0b00111, "", "Atlys strapping", "medium", "PHYAD[4:0] as strapped on the board"),
    "reg_status": Fact(17, "", "88E1111 register 17", "high", "PHY specific status"),
    "status_link_bit": Fact(10, "", "88E1111 register 17.10", "high", "link (real time)"),
    "status_speed_lsb": Fact(14, "", "88E1111 register 17.15:14", "high", "10 = 1000, 01 = 100, 00 = 10 Mb/s"),
    "status_resolved_bit": Fact(11, "", "88E1111 register 17.11", "high", "speed and duplex resolved"),
}
