"""The 1000BASE-X PCS (IEEE 802.3 clause 36): the transmit process with its encoder, and the
receive chain: comma alignment, decoder, synchronisation, receive process; and clause 37
auto-negotiation, whose ``xmit`` says what the transmitter sends between frames and when frames
pass each way.

Both sides run in ``sync``, at 125 MHz for 1000BASE-X; rename the domain for the
transceiver's clocks (the receive side then runs on the recovered clock, the transmit side on
the reference clock, and the MAC on each).
"""

from amaranth import Module, Mux, Signal
from amaranth.lib import stream, wiring
from amaranth.lib.wiring import In, Out

from .align import Aligner
from .autoneg import AutoNegotiation, Xmit
from .code_groups import Decoder
from .receive import Receiver, RxPins
from .sync import Synchroniser
from .transmit import Transmitter, TxPins

__all__ = ["Pcs"]


class Pcs(wiring.Component):
    """GMII on one side, the transceiver's 10-bit words on the other, 8b/10b in fabric.

    With ``autoneg`` (the default) the PCS negotiates with its link partner (clause 37) and
    frames pass only in LINK_OK: the gates each way open and close only between frames, so a frame
    is given whole or not at all (one the MAC sends while the link is down is dropped). Without,
    it sends ``config`` while ``configuring`` and passes frames always.

    Parameters
    ----------
    autoneg : bool
    link_timer : int
        Auto-negotiation's link timer in cycles (10 ms nominal).
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
        Without ``autoneg``: send /C/ ordered sets carrying ``config`` between frames.
    config : In(16)
        Without ``autoneg``.
    mr_an_enable, mr_restart_an, pause, mr_adv_ability, mr_lp_adv_ability, mr_an_complete, xmit, restarts
        With ``autoneg``: those of :class:`~.autoneg.AutoNegotiation`.
    configs : Out(stream.Signature(16, always_ready=True))
        Configuration words received.
    sync_status : Out(1)
    losses : Out(counter_width)
        Times sync was lost.
    slips : Out(counter_width)
        Times the code-group boundary moved.
    """

    def __init__(self, *, autoneg=True, link_timer=1_250_000, counter_width=16):
        self._counter_width = counter_width
        #: The auto-negotiation machine, reachable for tests; ``None`` without ``autoneg``.
        self.autoneg = AutoNegotiation(link_timer=link_timer, counter_width=counter_width) if autoneg else None
        ports = {
            "gmii_tx": In(TxPins),
            "tx_code": Out(10),
            "rx_bits": In(10),
            "gmii_rx": Out(RxPins),
            "signal_detect": In(1, init=1),
            "configs": Out(stream.Signature(16, always_ready=True)),
            "sync_status": Out(1),
            "losses": Out(counter_width),
            "slips": Out(counter_width),
        }
        if autoneg:
            ports.update({
                "mr_an_enable": In(1, init=1), "mr_restart_an": In(1), "pause": In(2),
                "mr_adv_ability": Out(16), "mr_lp_adv_ability": Out(16), "mr_an_complete": Out(1),
                "xmit": Out(Xmit), "restarts": Out(counter_width),
            })
        else:
            ports.update({"configuring": In(1), "config": In(16)})
        super().__init__(ports)

    def elaborate(self, platform):
        m = Module()
        width = self._counter_width
        m.submodules.transmitter = tx = Transmitter()
        m.submodules.aligner = aligner = Aligner(counter_width=width)
        m.submodules.decoder = decoder = Decoder()
        m.submodules.synchroniser = sync = Synchroniser(counter_width=width)
        m.submodules.receiver = rx = Receiver()
        m.d.comb += [
            self.tx_code.eq(tx.code),
            aligner.bits.eq(self.rx_bits),
            decoder.code.eq(aligner.code),
            sync.received.eq(decoder.group),
            sync.signal_detect.eq(self.signal_detect),
            rx.group.eq(sync.group), rx.even.eq(sync.even), rx.sync_status.eq(sync.sync_status),
            self.sync_status.eq(sync.sync_status),
            self.losses.eq(sync.losses),
            self.slips.eq(aligner.slips),
        ]
        wiring.connect(m, wiring.flipped(self.configs), rx.configs)
        if self.autoneg is None:
            m.d.comb += [tx.gmii.eq(self.gmii_tx), tx.configuring.eq(self.configuring), tx.config.eq(self.config),
                         self.gmii_rx.eq(rx.gmii)]
            return m
        m.submodules.autoneg = an = self.autoneg
        m.d.comb += [
            an.configs.valid.eq(rx.configs.valid), an.configs.payload.eq(rx.configs.payload),
            an.idle.eq(rx.idle), an.invalid.eq(rx.invalid), an.sync_status.eq(sync.sync_status),
            an.mr_an_enable.eq(self.mr_an_enable), an.mr_restart_an.eq(self.mr_restart_an),
            an.pause.eq(self.pause),
            self.mr_adv_ability.eq(an.mr_adv_ability), self.mr_lp_adv_ability.eq(an.mr_lp_adv_ability),
            self.mr_an_complete.eq(an.mr_an_complete), self.xmit.eq(an.xmit), self.restarts.eq(an.restarts),
            tx.configuring.eq(an.xmit == Xmit.CONFIGURATION), tx.config.eq(an.tx_config),
        ]
        # The gates open and close only between frames: each changes only while its side is idle.
        data = an.xmit == Xmit.DATA
        tx_open, rx_open = Signal(), Signal()
        with m.If(~self.gmii_tx.en):
            m.d.sync += tx_open.eq(data)
        with m.If(~rx.gmii.dv):
            m.d.sync += rx_open.eq(data)
        m.d.comb += [tx.gmii.eq(Mux(tx_open, self.gmii_tx, 0)), self.gmii_rx.eq(Mux(rx_open, rx.gmii, 0))]
        return m
