"""The whole Ethernet side of a device: GMII pins in and out, its endpoint's ports in ``sync``.

:class:`EthernetPort` puts the MACs (:mod:`gateware.mac`) around an endpoint: the projector's
(:class:`~gateware.protocol.endpoint.Endpoint`: image rows, settings, sequencer registers) or a
sync master's (:class:`~gateware.protocol.master.MasterEndpoint`); a top uses it as one block. Three clock
domains: ``gmii_rx`` (the PHY's receive clock), ``gmii_tx`` (the transmit clock the FPGA drives)
and ``sync`` (the rest of the design, any frequency that keeps up with 125 MB/s).
"""

from amaranth import Module, Signal
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out, connect

from ..compose import forward, members
from ..mac import gmii
from ..mac.gmii_rx import counters_layout
from ..mac.path import ReceivePath, TransmitPath

__all__ = ["EthernetPort", "report_port"]


class EthernetPort(wiring.Component):
    """GMII receive MAC -> endpoint (stack and application protocol) -> GMII transmit MAC.

    Parameters
    ----------
    endpoint : wiring.Component
        The stack and protocol: ``rx`` and ``tx`` byte streams (:class:`~gateware.mac.layouts.ByteBeat`)
        in ``sync``, and its own ports, which become this port's.
    max_frame : int
        Longest frame the receive MAC accepts, FCS included.
    rx_depth : int
        Receive FIFO bytes (``gmii_rx`` -> ``sync``); the default holds a whole jumbo frame, so
        when ``sync`` falls behind frames are dropped whole.
    tx_depth : int
        Transmit FIFO bytes (``sync`` -> ``gmii_tx``); replies are sent once wholly buffered.

    Members
    -------
    gmii_rx : In(:class:`gmii.RxPins`)
        PHY receive pins, in ``gmii_rx``.
    gmii_tx : Out(:class:`gmii.TxPins`)
        PHY transmit pins, in ``gmii_tx``: ARP, ICMP echo and status replies.
    mac_counters : Out(:func:`gateware.mac.gmii_rx.counters_layout`)
        Frames seen on the receive pins per MAC verdict (good, bad FCS, rx_er, runt, oversize,
        preamble), carried into ``sync``.
    rx_dropped : Out(32)
        Frames dropped whole because the receive FIFO had no room (``sync`` fell behind).
    tx_underruns : Out(32)
        Frames aborted on the transmit pins because their bytes came late.
    (the endpoint's members but ``rx`` and ``tx``)
        In ``sync`` (an image record's first pixel leaves only after its frame passed every
        check, FCS included).
    """

    def __init__(self, endpoint, *, max_frame=gmii.MAX_JUMBO_FRAME_BYTES, rx_depth=16384, tx_depth=2048):
        self._rx = ReceivePath(max_frame=max_frame, depth=rx_depth)
        self._tx = TransmitPath(depth=tx_depth)
        self._endpoint = endpoint
        super().__init__({
            "gmii_rx": In(gmii.RxPins),
            "gmii_tx": Out(gmii.TxPins),
            "mac_counters": Out(counters_layout(32)),
            "rx_dropped": Out(32),
            "tx_underruns": Out(32),
            **members(self._endpoint, exclude=("rx", "tx")),
        })

    def elaborate(self, platform):
        m = Module()
        m.submodules.rx = rx = self._rx
        m.submodules.endpoint = endpoint = self._endpoint
        m.submodules.tx = tx = self._tx

        # -- MAC receive: pins (gmii_rx) -> frames in sync ---------------------------------------
        # The receive FIFO takes every byte at line rate; the endpoint's ``rx.ready`` gaps (a few
        # cycles after each frame) are far shorter than the 24 line cycles between frames.
        m.d.comb += rx.gmii.eq(self.gmii_rx)
        connect(m, rx.frames, endpoint.rx)

        # -- Stack and application protocol (sync): the endpoint's own ports ---------------------
        forward(m, self, endpoint)

        # -- MAC transmit: replies in sync -> pins (gmii_tx) --------------------------------------
        connect(m, endpoint.tx, tx.frames)
        m.d.comb += self.gmii_tx.eq(tx.gmii)

        # -- MAC counters, carried into sync -----------------------------------------------------
        m.d.comb += [
            self.mac_counters.eq(rx.counters),
            self.rx_dropped.eq(rx.dropped),
            self.tx_underruns.eq(tx.underruns),
        ]
        return m


def report_port(m, port, status, clock_hz):
    """What every status reply says of the device and its port, into ``status`` (a view with the
    fields of those names: ``uptime_cycles``, ``clock_hz``, ``mac_*``): ``sync`` cycles since
    reset, ``clock_hz`` (the ``sync`` clock), and ``port``'s MAC verdicts and losses."""
    uptime = Signal(48)
    m.d.sync += uptime.eq(uptime + 1)
    m.d.comb += [status.uptime_cycles.eq(uptime), status.clock_hz.eq(int(clock_hz)),
                 status.mac_rx_dropped.eq(port.rx_dropped), status.mac_tx_underruns.eq(port.tx_underruns)]
    for verdict, _ in port.mac_counters.shape():
        m.d.comb += status[f"mac_{verdict}"].eq(port.mac_counters[verdict])
