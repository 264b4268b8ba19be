"""The whole Ethernet side of the projector: GMII pins in and out, image rows and settings in ``sync``.

:class:`EthernetPort` composes the layers built and tested on their own; the system top uses it
as one block. Three clock domains: ``gmii_rx`` (the PHY's receive clock), ``gmii_tx`` (the
transmit clock the FPGA drives) and ``sync`` (the rest of the design, any frequency that keeps up
with 125 MB/s).
"""

from amaranth import Module
from amaranth.lib import stream, wiring
from amaranth.lib.wiring import In, Out, connect

from ..bitplane import pixel_layout
from ..dlpc410.params import Registers
from ..mac import gmii
from ..mac.gmii_rx import counters_layout
from ..mac.path import ReceivePath, TransmitPath
from ..protocol import fields
from .ingest import Config, Ingest, Status

__all__ = ["EthernetPort"]


class EthernetPort(wiring.Component):
    """GMII receive MAC -> stack and application protocol -> GMII transmit MAC.

    Parameters
    ----------
    dmd : :class:`gateware.dlpc410.facts.DmdType`
    mac, ip, port : int
        Addresses at reset (build parameters); a control record may change them.
    armed : bool
        Whether triggers reach the sequencer at reset; a control record may change it.
    frame_bits : int
        Width of the frame tag on ``pixels``.
    max_frame : int
        Longest frame the receive MAC accepts, FCS included.
    rx_depth : int
        Receive FIFO bytes (``gmii_rx`` -> ``sync``); the default holds a whole jumbo frame, so
        when ``sync`` falls behind frames are dropped whole.
    tx_depth : int
        Transmit FIFO bytes (``sync`` -> ``gmii_tx``); replies are sent once wholly buffered.
    buffer_depth : int
        Bytes of the stack's receive ring (store-and-forward of one frame).

    Members
    -------
    gmii_rx : In(:class:`gmii.RxPins`)
        PHY receive pins, in ``gmii_rx``.
    gmii_tx : Out(:class:`gmii.TxPins`)
        PHY transmit pins, in ``gmii_tx``: ARP, ICMP echo and status replies.
    pixels : Out(stream.Signature(pixel_layout(dmd, 1, frame_bits)))
        Image rows of accepted image records, in ``sync``, for
        :class:`gateware.bitplane.Serialiser` (``lanes=1``). A record's first pixel leaves only
        after its frame passed every check, FCS included.
    settings : Out(:data:`.ingest.Config`)
        Run-time configuration (reset value: the build parameters), in ``sync``.
    trigger : Out(1)
        Software trigger pulse, in ``sync``.
    registers : Out(stream.Signature(Registers))
        The sequencer's register set of each valid sequencer record, in ``sync``.
    status : In(:data:`.ingest.Status`)
        Figures from the rest of the system, reported in status replies, in ``sync``.
    mac_counters : Out(:func:`gateware.mac.gmii_rx.counters_layout`)
        Frames seen on the receive pins per MAC verdict (good, bad FCS, rx_er, runt, oversize,
        preamble), carried into ``sync``.
    rx_dropped : Out(32)
        Frames dropped whole because the receive FIFO had no room (``sync`` fell behind).
    tx_underruns : Out(32)
        Frames aborted on the transmit pins because their bytes came late.
    net_counters : Out(fields.layout(fields.NET_COUNTERS))
        Stack counters: frames, accepted, drops per cause (``drop_mac`` counts frames the MAC
        marked bad), replies.
    app_counters : Out(fields.layout(fields.APP_COUNTERS))
        Application counters: records per type, drops per cause, rows, payload bytes.
    """

    def __init__(self, dmd, *, mac, ip, port, armed=False, frame_bits=4, max_frame=gmii.MAX_JUMBO_FRAME_BYTES,
                 rx_depth=16384, tx_depth=2048, buffer_depth=16384):
        self._rx = ReceivePath(max_frame=max_frame, depth=rx_depth)
        self._tx = TransmitPath(depth=tx_depth)
        self._ingest = Ingest(dmd, mac=mac, ip=ip, port=port, armed=armed, frame_bits=frame_bits,
                              buffer_depth=buffer_depth)
        super().__init__({
            "gmii_rx": In(gmii.RxPins),
            "gmii_tx": Out(gmii.TxPins),
            "pixels": Out(stream.Signature(pixel_layout(dmd, 1, frame_bits))),
            "settings": Out(Config, init=self._ingest.signature.members["settings"].init),
            "trigger": Out(1),
            "registers": Out(stream.Signature(Registers)),
            "status": In(Status),
            "mac_counters": Out(counters_layout(32)),
            "rx_dropped": Out(32),
            "tx_underruns": Out(32),
            "net_counters": Out(fields.layout(fields.NET_COUNTERS)),
            "app_counters": Out(fields.layout(fields.APP_COUNTERS)),
        })

    def elaborate(self, platform):
        m = Module()
        m.submodules.rx = rx = self._rx
        m.submodules.ingest = ingest = self._ingest
        m.submodules.tx = tx = self._tx

        # -- MAC receive: pins (gmii_rx) -> frames in sync ---------------------------------------
        # The receive FIFO takes every byte at line rate; the ingest's ``rx.ready`` gaps (a few
        # cycles after each frame) are far shorter than the 24 line cycles between frames.
        m.d.comb += rx.gmii.eq(self.gmii_rx)

        # -- Stack and application protocol (sync) ------------------------------------------------
        connect(m, rx.frames, ingest.rx)
        connect(m, ingest.pixels, wiring.flipped(self.pixels))
        connect(m, ingest.registers, wiring.flipped(self.registers))
        m.d.comb += [
            self.settings.eq(ingest.settings),
            self.trigger.eq(ingest.trigger),
            ingest.status.eq(self.status),
        ]

        # -- MAC transmit: replies in sync -> pins (gmii_tx) --------------------------------------
        connect(m, ingest.tx, tx.frames)
        m.d.comb += self.gmii_tx.eq(tx.gmii)

        # -- Counters, all in sync ---------------------------------------------------------------
        m.d.comb += [
            self.mac_counters.eq(rx.counters),
            self.rx_dropped.eq(rx.dropped),
            self.tx_underruns.eq(tx.underruns),
            self.net_counters.eq(ingest.net_counters),
            self.app_counters.eq(ingest.app_counters),
        ]
        return m
