"""The 1000BASE-X PCS (IEEE 802.3 clause 36): the transmit process with its encoder, and the
receive chain: comma alignment, decoder, synchronisation, receive process.

Both sides run in ``sync``, at 125 MHz for 1000BASE-X; rename the domain for the
transceiver's clocks (the receive side then runs on the recovered clock, the transmit side on
the reference clock, and the MAC on each).
"""

from amaranth import Module
from amaranth.lib import stream, wiring
from amaranth.lib.wiring import In, Out

from .align import Aligner
from .code_groups import Decoder
from .receive import Receiver, RxPins
from .sync import Synchroniser
from .transmit import Transmitter, TxPins

__all__ = ["Pcs"]


class Pcs(wiring.Component):
    """GMII on one side, the transceiver's 10-bit words on the other, 8b/10b in fabric.

    Parameters
    ----------
    counter_width : int

    Members
    -------
    gmii_tx : In(:class:`TxPins`)
        From the MAC.
    tx_code : Out(10)
        To the transceiver (its own 8b/10b bypassed), first bit in bit 0, a cycle after
        the pins.
    rx_bits : In(10)
        From the transceiver, first bit in bit 0, at any bit offset.
    gmii_rx : Out(:class:`RxPins`)
        To the MAC, four register stages (aligner, decoder, synchroniser, receiver) after the
        word that ends the code-group came in ``rx_bits``.
    signal_detect : In(1, init=1)
    configuring : In(1)
        Send /C/ ordered sets carrying ``config`` between frames.
    config : In(16)
    configs : Out(stream.Signature(16, always_ready=True))
        Configuration words received.
    sync_status : Out(1)
    losses : Out(counter_width)
        Times sync was lost.
    slips : Out(counter_width)
        Times the code-group boundary moved.
    """

    def __init__(self, *, counter_width=16):
        self._counter_width = counter_width
        super().__init__({
            "gmii_tx": In(TxPins),
            "tx_code": Out(10),
            "rx_bits": In(10),
            "gmii_rx": Out(RxPins),
            "signal_detect": In(1, init=1),
            "configuring": In(1),
            "config": In(16),
            "configs": Out(stream.Signature(16, always_ready=True)),
            "sync_status": Out(1),
            "losses": Out(counter_width),
            "slips": Out(counter_width),
        })

    def elaborate(self, platform):
        m = Module()
        width = self._counter_width
        m.submodules.transmitter = tx = Transmitter()
        m.submodules.aligner = aligner = Aligner(counter_width=width)
        m.submodules.decoder = decoder = Decoder()
        m.submodules.synchroniser = sync = Synchroniser(counter_width=width)
        m.submodules.receiver = rx = Receiver()
        m.d.comb += [
            tx.gmii.eq(self.gmii_tx), tx.configuring.eq(self.configuring), tx.config.eq(self.config),
            self.tx_code.eq(tx.code),
            aligner.bits.eq(self.rx_bits),
            decoder.code.eq(aligner.code),
            sync.received.eq(decoder.group),
            sync.signal_detect.eq(self.signal_detect),
            rx.group.eq(sync.group), rx.even.eq(sync.even), rx.sync_status.eq(sync.sync_status),
            self.gmii_rx.eq(rx.gmii),
            self.sync_status.eq(sync.sync_status),
            self.losses.eq(sync.losses),
            self.slips.eq(aligner.slips),
        ]
        wiring.connect(m, wiring.flipped(self.configs), rx.configs)
        return m
