"""The 1000BASE-X PCS (IEEE 802.3 clause 36): the transmit process with its encoder, and the
receive chain: comma alignment, decoder, synchronisation, receive process; and clause 37
auto-negotiation, whose ``xmit`` says what the transmitter sends between frames and when frames
pass each way.

Both sides run in ``sync`` by default, at 125 MHz for 1000BASE-X. On a transceiver they run in
two domains (``tx_domain``, ``rx_domain``): the transmit side on the transmit user clock, the
receive chain and auto-negotiation on the recovered clock, with ``xmit`` and the configuration
word to send carried into the transmit domain by synchronisers. Both change only every link
timer or so: a word torn in the crossing is sent in one ordered set and, differing from its
neighbours, never counted as three alike by the partner.
"""

from amaranth import DomainRenamer, Module, Mux, Signal
from amaranth.lib import stream, wiring
from amaranth.lib.cdc import FFSynchronizer
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
    tx_domain, rx_domain : str
        The domains of the transmit side (``gmii_tx``, ``tx_code``) and of the rest (``rx_bits``,
        ``gmii_rx``, the status and auto-negotiation ports); both ``sync`` by default.

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

    def __init__(self, *, autoneg=True, link_timer=1_250_000, counter_width=16, tx_domain="sync",
                 rx_domain="sync"):
        self._counter_width = counter_width
        self._tx_domain, self._rx_domain = tx_domain, rx_domain
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
        txd, rxd = self._tx_domain, self._rx_domain
        tx, aligner = Transmitter(), Aligner(counter_width=width)
        decoder, sync, rx = Decoder(), Synchroniser(counter_width=width), Receiver()
        m.submodules.transmitter = DomainRenamer(txd)(tx) if txd != "sync" else tx
        for name, block in (("aligner", aligner), ("decoder", decoder), ("synchroniser", sync), ("receiver", rx)):
            m.submodules[name] = DomainRenamer(rxd)(block) if rxd != "sync" else block
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
        an = self.autoneg
        m.submodules.autoneg = DomainRenamer(rxd)(an) if rxd != "sync" else an
        # what the transmitter takes from auto-negotiation, in the transmit domain
        xmit, tx_config = Signal(Xmit), Signal(16)
        if txd == rxd:
            m.d.comb += [xmit.eq(an.xmit), tx_config.eq(an.tx_config)]
        else:
            m.submodules.xmit_sync = FFSynchronizer(an.xmit.as_value(), xmit.as_value(), o_domain=txd)
            m.submodules.config_sync = FFSynchronizer(an.tx_config, tx_config, o_domain=txd)
        m.d.comb += [
            an.configs.valid.eq(rx.configs.valid), an.configs.payload.eq(rx.configs.payload),
            an.idle.eq(rx.idle), an.invalid.eq(rx.invalid), an.sync_status.eq(sync.sync_status),
            an.mr_an_enable.eq(self.mr_an_enable), an.mr_restart_an.eq(self.mr_restart_an),
            an.pause.eq(self.pause),
            self.mr_adv_ability.eq(an.mr_adv_ability), self.mr_lp_adv_ability.eq(an.mr_lp_adv_ability),
            self.mr_an_complete.eq(an.mr_an_complete), self.xmit.eq(an.xmit), self.restarts.eq(an.restarts),
            tx.configuring.eq(xmit == Xmit.CONFIGURATION), tx.config.eq(tx_config),
        ]
        # The gates open and close only between frames: each changes only while its side is idle.
        tx_open, rx_open = Signal(), Signal()
        with m.If(~self.gmii_tx.en):
            m.d[txd] += tx_open.eq(xmit == Xmit.DATA)
        with m.If(~rx.gmii.dv):
            m.d[rxd] += rx_open.eq(an.xmit == Xmit.DATA)
        m.d.comb += [tx.gmii.eq(Mux(tx_open, self.gmii_tx, 0)), self.gmii_rx.eq(Mux(rx_open, rx.gmii, 0))]
        return m
