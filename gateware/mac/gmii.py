"""GMII pins and the IEEE 802.3 framing numbers the MAC is built on.

GMII (IEEE 802.3 clause 35) moves one byte per 125 MHz clock in each direction: ``rx_d/rx_dv/rx_er``
from the PHY (on ``RX_CLK``), ``tx_d/tx_en/tx_er`` to it (on ``GTX_CLK``). A frame on the wire is
preamble bytes (0x55), the start frame delimiter (0xD5), destination MAC .. payload, and a
32-bit FCS sent least significant byte first, followed by an inter-frame gap.
"""

from amaranth.lib import crc, data

__all__ = [
    "RxPins", "TxPins", "fcs_parameters",
    "PREAMBLE_BYTE", "SFD_BYTE", "PREAMBLE_BYTES", "FCS_BYTES", "MIN_FRAME_BYTES",
    "MAX_JUMBO_FRAME_BYTES", "MIN_GAP_BYTES",
]

#: Preamble byte, and the start frame delimiter that ends the preamble (IEEE 802.3 clause 3.2.1-2).
PREAMBLE_BYTE = 0x55
SFD_BYTE = 0xD5
#: Preamble bytes a transmitter sends before the SFD (the receiver does not insist on them).
PREAMBLE_BYTES = 7
#: Frame check sequence length (clause 3.2.9).
FCS_BYTES = 4
#: Shortest frame, destination MAC to FCS inclusive (clause 4.4.2, minFrameSize = 512 bits).
MIN_FRAME_BYTES = 64
#: Longest frame we accept by default: a 9,000-byte MTU jumbo frame with header, VLAN tag and FCS.
MAX_JUMBO_FRAME_BYTES = 9018
#: Minimum inter-frame gap, in byte times (clause 4.4.2, interPacketGap = 96 bits).
MIN_GAP_BYTES = 12


class RxPins(data.Struct):
    """GMII receive pins, sampled on the PHY's receive clock."""
    d: 8
    dv: 1
    er: 1


class TxPins(data.Struct):
    """GMII transmit pins, driven on the transmit clock."""
    d: 8
    en: 1
    er: 1


def fcs_parameters():
    """The Ethernet FCS: CRC-32 (the ``CRC32_ETHERNET`` catalog entry) over bytes.

    Its ``crc`` output equals :func:`zlib.crc32` of the bytes processed and goes on the wire least
    significant byte first; run over the bytes and their FCS, the register holds the residue.
    """
    return crc.catalog.CRC32_ETHERNET(data_width=8)
