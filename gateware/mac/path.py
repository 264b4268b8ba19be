"""The MAC as the stack sees it: GMII pins on one side, ``sync``-domain byte streams on the other.

:class:`ReceivePath` is :class:`gmii_rx.Receiver` followed by :class:`cdc.RxCrossing`;
:class:`TransmitPath` is :class:`cdc.TxCrossing` followed by :class:`gmii_tx.Transmitter`.
Their counters are carried into ``sync`` with :class:`gateware.cdc.CountSynchronizer`, so the status
logic reads every figure in its own domain.
"""

from amaranth import DomainRenamer, Module
from amaranth.lib import stream, wiring
from amaranth.lib.wiring import In, Out

from ..cdc import CountSynchronizer
from ..queue import Queue
from . import gmii
from .cdc import RxCrossing, TxCrossing
from .gmii_rx import Receiver, counters_layout
from .gmii_tx import Transmitter
from .layouts import ByteBeat

__all__ = ["ReceivePath", "TransmitPath"]

#: Bytes of each registered stage around the transmit crossing (three keep a byte a cycle flowing).
_STAGE_DEPTH = 4


class ReceivePath(wiring.Component):
    """GMII receive MAC and its crossing into ``sync``.

    Parameters
    ----------
    max_frame : int
        Longest good frame, FCS included.
    depth : int
        Receive FIFO depth in bytes (a power of 2); the default holds a whole jumbo frame, so
        frames are dropped whole when the consumer falls behind and never cut.
    counter_width : int

    Members
    -------
    gmii : In(:class:`gmii.RxPins`)
        PHY receive pins, in ``gmii_rx``.
    frames : Out(stream.Signature(:class:`ByteBeat`))
        Received frames in ``sync``, destination MAC to payload; ``user`` on ``last`` = bad
        (FCS, rx_er, runt, oversize, or cut by the FIFO). Consumers must discard bad frames.
    counters : Out(:func:`gmii_rx.counters_layout`)
        Frames per verdict, in ``sync``.
    dropped : Out(counter_width)
        Frames dropped or cut because ``frames`` fell behind, in ``sync``.
    """

    def __init__(self, *, max_frame=gmii.MAX_JUMBO_FRAME_BYTES, depth=16384, counter_width=32):
        self._max_frame, self._depth, self._counter_width = max_frame, depth, counter_width
        super().__init__({
            "gmii": In(gmii.RxPins),
            "frames": Out(stream.Signature(ByteBeat)),
            "counters": Out(counters_layout(counter_width)),
            "dropped": Out(counter_width),
        })

    def elaborate(self, platform):
        m = Module()
        width = self._counter_width
        m.submodules.mac = mac = Receiver(max_frame=self._max_frame, counter_width=width)
        m.submodules.crossing = crossing = RxCrossing(depth=self._depth, max_frame=self._max_frame,
                                                      counter_width=width)
        m.d.comb += mac.gmii.eq(self.gmii)
        # Both ends are always ready: the crossing takes every byte (GMII has no backpressure).
        wiring.connect(m, mac.frames, crossing.i)
        wiring.connect(m, crossing.o, wiring.flipped(self.frames))

        pairs = [(mac.counters[name], self.counters[name]) for name, _ in counters_layout(width)]
        for i, (counter, out) in enumerate([*pairs, (crossing.dropped, self.dropped)]):
            sync = m.submodules[f"counter_cdc{i}"] = CountSynchronizer(width, i_domain="gmii_rx",
                                                                       o_domain="sync")
            m.d.comb += [sync.i.eq(counter), out.eq(sync.o)]
        return m


class TransmitPath(wiring.Component):
    """The crossing from ``sync`` and the GMII transmit MAC.

    Parameters
    ----------
    depth : int
        Transmit FIFO depth in bytes (a power of 2); frames up to this long are sent only once
        wholly buffered, so they never underrun.
    counter_width : int

    Members
    -------
    frames : In(stream.Signature(:class:`ByteBeat`))
        Frames to send, in ``sync``, destination MAC to payload (padding and FCS are added);
        ``user`` on ``last`` aborts the frame (sent with a bad FCS).
    gmii : Out(:class:`gmii.TxPins`)
        PHY transmit pins, in ``gmii_tx``.
    underruns : Out(counter_width)
        Frames aborted because their bytes did not arrive in time, in ``sync``.
    """

    def __init__(self, *, depth=2048, counter_width=32):
        self._depth, self._counter_width = depth, counter_width
        super().__init__({
            "frames": In(stream.Signature(ByteBeat)),
            "gmii": Out(gmii.TxPins),
            "underruns": Out(counter_width),
        })

    def elaborate(self, platform):
        m = Module()
        m.submodules.crossing = crossing = TxCrossing(depth=self._depth)
        m.submodules.mac = mac = Transmitter(counter_width=self._counter_width)
        # registered stages on both sides of the crossing: the sender's logic, the FIFO's flags
        # and frame counts, and the MAC's next byte are each a cycle's logic, not one path
        m.submodules.entry = entry = Queue(ByteBeat, depth=_STAGE_DEPTH)
        wiring.connect(m, wiring.flipped(self.frames), entry.w_stream)
        wiring.connect(m, entry.r_stream, crossing.i)
        m.submodules.stage = stage = DomainRenamer("gmii_tx")(Queue(ByteBeat, depth=_STAGE_DEPTH))
        wiring.connect(m, crossing.o, stage.w_stream)
        wiring.connect(m, stage.r_stream, mac.frames)
        m.d.comb += self.gmii.eq(mac.gmii)
        m.submodules.underruns_cdc = sync = CountSynchronizer(self._counter_width,
                                                              i_domain="gmii_tx", o_domain="sync")
        m.d.comb += [sync.i.eq(mac.underruns), self.underruns.eq(sync.o)]
        return m
