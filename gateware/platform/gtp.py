"""One lane of the Spartan-6 GTP transceiver (``GTPA1_DUAL``) as a 10-bit, 125 MHz, 1.25 Gb/s link.

The GTP's own 8b/10b encoder and decoder, comma detection and alignment, clock correction and
loss-of-sync machine are all off: :class:`gateware.pcs.Pcs` does them in fabric. The GTP only
serialises the transmit words and deserialises the received bits, at whatever bit offset the
line gives (the PCS's aligner finds the comma).

Settings and their sources
--------------------------
Port and attribute names are those of Xilinx's ``GTPA1_DUAL`` unisim as Yosys's Xilinx cell
library declares it (``cells_xtra.v``, which the board lint reads too). The values for 1.25 Gb/s
from a 125 MHz reference follow CERN's White Rabbit core for the Spartan-6 (wr-cores,
``platform/xilinx/wr_gtp_phy/spartan6/``: ``wr_gtp_phy_spartan6.vhd`` and
``whiterabbitgtp_wrapper_tile_spartan6.vhd``), a 1.25 Gb/s link from 125 MHz on the SPEC and SVEC:

* ``PLL_DIVSEL_FB = 2``, ``PLL_DIVSEL_REF = 1``, internal data path 10 bits
  (``INTDATAWIDTH = 1``): the PLL runs at 125 MHz x 2 x 5 = 1.25 GHz;
  ``PLL_TXDIVSEL_OUT = PLL_RXDIVSEL_OUT = 2``: 1.25 Gb/s each way (UG386's PLL and line-rate
  equations, as wr-cores applies them; not checked against UG386's tables here).
* ``CLK25_DIVIDER = 5`` (125 MHz / 5 = 25 MHz), ``PLL_COM_CFG``, ``PLL_CP_CFG``,
  ``PLLLKDET_CFG``, ``PMA_RX_CFG``, ``PMA_CDR_SCAN``, ``PMA_TX_CFG``, the termination and
  ``GTPTEST`` values: wr-cores'.
* One byte a cycle each way (``TXDATAWIDTH = RXDATAWIDTH = 0``): TXUSRCLK = TXUSRCLK2 and
  RXUSRCLK = RXUSRCLK2, all 125 MHz.
* Transmit: the TX buffer is used (``TX_BUFFER_USE = TRUE``, ``TX_XCLK_SEL = TXOUT``), so no
  TX phase alignment is needed; TXUSRCLK is ``GTPCLKOUT[0]`` (the PLL's reference clock,
  ``CLK_OUT_GTP_SEL = REFCLKPLL``) through a BUFIO2 and a BUFG. (wr-cores bypasses the buffer
  for a fixed latency and runs the phase alignment; we do not need the fixed latency.)
* Receive: the RX elastic buffer is used but clocked on the recovered clock on both sides
  (``RX_BUFFER_USE = TRUE``, ``RX_XCLK_SEL = RXREC``, RXUSRCLK = ``GTPCLKOUT[1]``, the
  recovered clock, through a BUFIO2 and a BUFG, as wr-cores does), so it only crosses phase and
  clock correction is off.
* 8b/10b bypassed (``TXENC8B10BUSE = RXDEC8B10BUSE = 0``): the 10-bit word is TXDATA[7:0] with
  TXCHARDISPVAL[0] as bit 8 and TXCHARDISPMODE[0] as bit 9; received, RXDATA[7:0] with
  RXCHARISK[0] as bit 8 and RXDISPERR[0] as bit 9.
* Reset: GTPRESET while the board is in reset; each user-clock domain is held in reset until
  both PLLLKDET and RESETDONE are set.

Bit order in 8b/10b bypass: UG386 itself was not at hand. Xilinx's later transceiver guides
say the GTP and GTX "always" send and receive "the right-most bit first" (TXDATA[0], RXDATA[0]:
hence their 8b/10b encoder and decoder reverse the code-group so that ``a`` goes first), and,
with the decoder bypassed and a 10-bit data width, that "RXDISPERR represents the 9th bit" and
"RXCHARISK the 8th bit" (7 Series GTP, UG482 v1.9, "RX 8B/10B Decoder"; Virtex-6 GTX, UG366
v2.5, "8B/10B Decoder Bit and Byte Order"); TXCHARDISPMODE and TXCHARDISPVAL are bits 9 and 8
on the transmit side. This wrapper follows them: bit 0 of :attr:`tx_code` (``a``) first on the
line, bit 9 received on RXDISPERR. The older RocketIO (UG024) is the other way round
(TXCHARDISPMODE first, RXRUNDISP as a received bit); ``msb_first=True`` reverses the word
should the Spartan-6 GTP turn out to be like it (to check on hardware, with UG386: see
``constraints/README.md``). Which GTP lane (0 or 1) the SVEC's SFP is on is also taken from the
board's pins, not confirmed from its schematic: ``lane`` says.
"""

from amaranth import Cat, ClockSignal, Const, Instance, Module, Signal
from amaranth.lib import wiring
from amaranth.lib.cdc import ResetSynchronizer
from amaranth.lib.wiring import In, Out

__all__ = ["Gtp", "gtp_parameters"]


def gtp_parameters(lane):
    """The ``GTPA1_DUAL`` attributes (``Instance`` ``p_`` keywords) for ``lane`` at 1.25 Gb/s from 125 MHz,
    the other lane's PLL powered down."""
    n = str(lane)
    params = {
        "CLK25_DIVIDER": 5, "PLL_DIVSEL_FB": 2, "PLL_DIVSEL_REF": 1, "PLL_TXDIVSEL_OUT": 2, "PLL_RXDIVSEL_OUT": 2,
        "PLL_SOURCE": f"PLL{n}", "PLL_SATA": "FALSE", "PLL_COM_CFG": Const(0x21680A, 24), "PLL_CP_CFG": Const(0, 8),
        "PLLLKDET_CFG": Const(0b111, 3), "CLKINDC_B": "TRUE", "CLKRCV_TRST": "TRUE", "OOB_CLK_DIVIDER": 4,
        "CLK_OUT_GTP_SEL": f"REFCLKPLL{n}", "TX_TDCC_CFG": Const(0, 2),
        "PMA_TX_CFG": Const(0x80082, 20), "TX_BUFFER_USE": "TRUE", "TX_XCLK_SEL": "TXOUT",
        "AC_CAP_DIS": "TRUE", "PMA_CDR_SCAN": Const(0x6404040, 27), "PMA_RX_CFG": Const(0x05CE048, 25),
        "RCV_TERM_GND": "FALSE", "RCV_TERM_VTTRX": "FALSE", "TERMINATION_OVRD": "FALSE",
        "RX_BUFFER_USE": "TRUE", "RX_XCLK_SEL": "RXREC", "RX_EN_IDLE_RESET_BUF": "TRUE",
        "MCOMMA_DETECT": "FALSE", "PCOMMA_DETECT": "FALSE", "DEC_MCOMMA_DETECT": "FALSE",
        "DEC_PCOMMA_DETECT": "FALSE", "RX_DECODE_SEQ_MATCH": "FALSE", "CLK_CORRECT_USE": "FALSE",
        "RX_LOSS_OF_SYNC_FSM": "FALSE", "PCI_EXPRESS_MODE": "FALSE",
    }
    return {f"p_{name}_{n}": value for name, value in params.items()}


class Gtp(wiring.Component):
    """One GTP lane: 10-bit words in ``tx_domain`` out on the line, the line's bits in ``rx_domain``.

    Drives both domains' clocks (TXUSRCLK, the recovered clock) and resets (held until the
    GTP's PLL locks and its reset is done); the domains themselves are the caller's.

    Parameters
    ----------
    pads : the board's ``sfp`` resource requested with ``dir="-"`` (``tx``, ``rx`` pairs)
    refclk : the board's ``sfp_refclk`` pair, requested with ``dir="-"``
    reset : Signal
        Holds the GTP in reset (GTPRESET).
    tx_domain, rx_domain : str
    lane : int
    msb_first : bool
        Send and receive bit 9 of a word first (see the module's notes).

    Members
    -------
    tx_code : In(10), in ``tx_domain``; first bit sent in bit 0
    rx_bits : Out(10), in ``rx_domain``; first bit received in bit 0, at any offset
    ready : Out(1), asynchronous: PLL locked and reset done
    """

    tx_code: In(10)
    rx_bits: Out(10)
    ready: Out(1)

    def __init__(self, pads, refclk, reset, *, tx_domain="gtp_tx", rx_domain="gtp_rx", lane=0, msb_first=False):
        assert lane in (0, 1)
        super().__init__()
        self._pads, self._refclk, self._reset = pads, refclk, reset
        self._tx_domain, self._rx_domain, self._lane, self._msb_first = tx_domain, rx_domain, lane, msb_first

    def elaborate(self, platform):
        m = Module()
        n, other = str(self._lane), str(1 - self._lane)
        refclk, plllkdet, resetdone = Signal(), Signal(), Signal()
        gtpclkout = Signal(2)
        txdata, rxdata = Signal(32), Signal(32)
        rxcharisk, rxdisperr = Signal(4), Signal(4)
        # bit 0 first on the line and RXDISPERR as bit 9 (UG482, UG366: see the module's notes)
        order = (lambda v: v[::-1]) if self._msb_first else (lambda v: v)
        tx_word, rx_word = order(self.tx_code), Signal(10)
        m.d.comb += [txdata.eq(tx_word[:8]), rx_word.eq(Cat(rxdata[:8], rxcharisk[0], rxdisperr[0])),
                     self.rx_bits.eq(order(rx_word))]

        m.submodules.refclk_buf = Instance("IBUFDS", i_I=self._refclk.p, i_IB=self._refclk.n, o_O=refclk)
        lane_ports = {
            "CLK0": refclk, "GTPRESET": self._reset, "PLLLKDETEN": 1, "PLLPOWERDOWN": 0, "REFCLKPWRDNB": 1,
            "PLLLKDET": plllkdet, "RESETDONE": resetdone, "INTDATAWIDTH": 1, "GTPTEST": Const(0b00010000, 8),
            "GTPCLKOUT": gtpclkout, "LOOPBACK": Const(0, 3), "RXPOWERDOWN": Const(0, 2), "TXPOWERDOWN": Const(0, 2),
            "TXUSRCLK": ClockSignal(self._tx_domain), "TXUSRCLK2": ClockSignal(self._tx_domain),
            "TXDATAWIDTH": Const(0, 2), "TXENC8B10BUSE": 0, "TXBYPASS8B10B": Const(0, 4), "TXCHARISK": Const(0, 4),
            "TXDATA": txdata, "TXCHARDISPVAL": Cat(tx_word[8], Const(0, 3)),
            "TXCHARDISPMODE": Cat(tx_word[9], Const(0, 3)), "TXRESET": 0, "TXPOLARITY": 0, "TXINHIBIT": 0,
            "TXELECIDLE": 0, "TXDIFFCTRL": Const(0b0110, 4), "TXBUFDIFFCTRL": Const(0b101, 3),
            "TXPREEMPHASIS": Const(0, 3), "TXENPRBSTST": Const(0, 3),
            "TXP": self._pads.tx.p, "TXN": self._pads.tx.n, "RXP": self._pads.rx.p, "RXN": self._pads.rx.n,
            "RXUSRCLK": ClockSignal(self._rx_domain), "RXUSRCLK2": ClockSignal(self._rx_domain),
            "RXDATAWIDTH": Const(0, 2), "RXDEC8B10BUSE": 0, "RXCOMMADETUSE": 0, "RXENMCOMMAALIGN": 0,
            "RXENPCOMMAALIGN": 0, "RXSLIDE": 0, "RXRESET": 0, "RXCDRRESET": 0, "RXBUFRESET": 0, "RXPOLARITY": 0,
            "RXEQMIX": Const(0, 2), "RXENPRBSTST": Const(0, 3), "GATERXELECIDLE": 0, "IGNORESIGDET": 1,
            "RXDATA": rxdata, "RXCHARISK": rxcharisk, "RXDISPERR": rxdisperr,
        }
        ports = {}
        for name, value in lane_ports.items():
            kind = "o" if name in ("PLLLKDET", "RESETDONE", "GTPCLKOUT", "TXP", "TXN", "RXDATA", "RXCHARISK",
                                   "RXDISPERR") else "i"
            # the clock inputs are CLK00/CLK01 (lane 0's, lane 1's): CLK<k><lane>
            key = f"CLK0{n}" if name == "CLK0" else f"{name}{n}"
            ports[f"{kind}_{key}"] = value
        # the unused lane: powered down, held in reset
        ports.update({f"i_GTPRESET{other}": 1, f"i_PLLPOWERDOWN{other}": 1, f"i_RXPOWERDOWN{other}": Const(3, 2),
                      f"i_TXPOWERDOWN{other}": Const(3, 2), f"i_REFCLKPWRDNB{other}": 0})
        m.submodules.gtp = Instance("GTPA1_DUAL", **gtp_parameters(self._lane), **ports)

        for index, domain in ((0, self._tx_domain), (1, self._rx_domain)):
            divclk = Signal(name=f"{domain}_divclk")
            m.submodules[f"{domain}_bufio2"] = Instance(
                "BUFIO2", p_DIVIDE=1, p_DIVIDE_BYPASS="TRUE", p_I_INVERT="FALSE", p_USE_DOUBLER="FALSE",
                i_I=gtpclkout[index], o_DIVCLK=divclk)
            m.submodules[f"{domain}_bufg"] = Instance("BUFG", i_I=divclk, o_O=ClockSignal(domain))
            if platform is not None and hasattr(platform, "add_clock_constraint"):
                platform.add_clock_constraint(divclk, 125e6)
            m.submodules[f"{domain}_rst"] = ResetSynchronizer(~self.ready, domain=domain)
        m.d.comb += self.ready.eq(plllkdet & resetdone)
        return m

