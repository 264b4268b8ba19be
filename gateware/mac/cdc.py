"""Clock-domain crossings of the MAC: frames through async FIFOs.

Receive (:class:`RxCrossing`, ``gmii_rx`` -> ``sync``)
------------------------------------------------------
GMII cannot be stalled, so the write side takes every byte the receive MAC emits, every cycle.
A consumer that keeps up with 125 MB/s never loses a byte (the FIFO only absorbs clock drift and
the crossing latency). When it does not keep up, frames are dropped whole and counted:

* a frame starts into the FIFO only if the free space then is larger than ``room`` (by default
  the longest frame the MAC forwards): otherwise none of its bytes is written;
* if the space still runs out mid-frame (only possible when ``depth`` is below the longest
  frame), the byte written into the last free slots is marked ``last`` with ``user`` = 1 and the
  rest of the frame is discarded, so the consumer sees a short frame flagged bad.

Either way ``dropped`` counts the frame, and no frame leaves with ``user`` = 0 unless every byte
of it went through. Why no write is ever refused: the free space is computed from the FIFO's
write-side level, which sees reads late (so never overstates the room) and misses only the write
of the previous cycle (so the true fill is at most one above it). A byte is written normally only
when that free space exceeds 2, leaving at least one truly free slot after it; the next write,
normal or the cut marker, therefore always fits, and after a marker nothing is written until a
frame start finds more than ``room`` free. (:mod:`tests.test_mac_cdc` checks that a margin of 1
loses bytes.)

Transmit (:class:`TxCrossing`, ``sync`` -> ``gmii_tx``)
-------------------------------------------------------
GMII cannot pause mid-frame either, so a frame is offered to the transmit MAC only when it is
wholly in the FIFO (a count of complete frames crosses in Gray code), or when the FIFO is full
(a frame longer than the FIFO: then the producer must refill it faster than the line drains it,
or the transmit MAC aborts the frame on underrun).
"""

from amaranth import Module, Mux, Signal
from amaranth.lib import stream, wiring
from amaranth.lib.fifo import AsyncFIFO
from amaranth.lib.wiring import In, Out
from amaranth.utils import ceil_log2

from ..cdc import CountSynchronizer
from . import gmii
from .layouts import ByteBeat

__all__ = ["RxCrossing", "TxCrossing"]


class RxCrossing(wiring.Component):
    """Receive frames from ``gmii_rx`` into ``sync``, dropping whole frames when full.

    Parameters
    ----------
    depth : int
        FIFO depth in bytes (a power of 2).
    room : int
        Free bytes a frame needs at its start to be let in; default: the longest frame the
        receive MAC forwards (``max_frame`` less the FCS), capped so that an empty FIFO admits.
    max_frame : int
        The receive MAC's limit, FCS included.
    counter_width : int
    w_domain, r_domain : str

    Members
    -------
    i : In(stream.Signature(ByteBeat, always_ready=True))
        Frames from :class:`gmii_rx.Receiver`, in ``w_domain``; taken every cycle.
    o : Out(stream.Signature(ByteBeat))
        The same frames in ``r_domain``, minus dropped ones.
    dropped : Out(counter_width)
        Frames dropped or truncated for lack of room, in ``w_domain``.
    """

    #: Free slots below which a frame is cut: one for the byte in flight, one for the marker.
    _MARGIN = 2

    def __init__(self, *, depth=16384, room=None, max_frame=gmii.MAX_JUMBO_FRAME_BYTES, counter_width=32,
                 w_domain="gmii_rx", r_domain="sync"):
        assert depth == 1 << ceil_log2(depth) and depth > 2 * self._MARGIN
        if room is None:
            room = min(max_frame - gmii.FCS_BYTES + self._MARGIN, depth - 1)
        assert self._MARGIN <= room < depth
        self._depth, self._room = depth, room
        self._w_domain, self._r_domain = w_domain, r_domain
        super().__init__({
            "i": In(stream.Signature(ByteBeat, always_ready=True)),
            "o": Out(stream.Signature(ByteBeat)),
            "dropped": Out(counter_width),
        })

    def elaborate(self, platform):
        m = Module()
        w = self._w_domain
        m.submodules.fifo = fifo = AsyncFIFO(width=len(self.i.payload.as_value()), depth=self._depth,
                                             w_domain=w, r_domain=self._r_domain)
        # The write side takes no notice of ``ready``: room is judged from the level (see above).
        into = fifo.w_stream
        wiring.connect(m, fifo.r_stream, wiring.flipped(self.o))

        free = Signal(range(self._depth + 1))
        m.d.comb += free.eq(self._depth - fifo.w_level)
        # Inside a frame that is being written, or being discarded (dropped or cut).
        writing = Signal()
        discarding = Signal()
        beat = self.i.payload
        cut = Signal()

        with m.If(self.i.valid):
            with m.If(writing):
                with m.If(free <= self._MARGIN):
                    # Out of room mid-frame: this byte ends the frame, marked bad.
                    m.d.comb += [cut.eq(1), into.valid.eq(1)]
                    m.d[w] += [writing.eq(0), discarding.eq(~beat.last), self.dropped.eq(self.dropped + 1)]
                with m.Else():
                    m.d.comb += into.valid.eq(1)
                    m.d[w] += writing.eq(~beat.last)
            with m.Elif(discarding):
                m.d[w] += discarding.eq(~beat.last)
            with m.Elif(free > self._room):
                m.d.comb += into.valid.eq(1)
                m.d[w] += writing.eq(~beat.last)
            with m.Else():
                m.d[w] += [discarding.eq(~beat.last), self.dropped.eq(self.dropped + 1)]

        marked = ByteBeat.const({"data": 0, "last": 1, "user": 1}).as_value()
        m.d.comb += into.payload.eq(Mux(cut, beat.as_value() | marked, beat.as_value()))
        return m


class TxCrossing(wiring.Component):
    """Transmit frames from ``sync`` into ``gmii_tx``, offered only once wholly buffered.

    Parameters
    ----------
    depth : int
        FIFO depth in bytes (a power of 2). Frames up to this long never underrun.
    w_domain, r_domain : str

    Members
    -------
    i : In(stream.Signature(ByteBeat))
        Frames to send, in ``w_domain``.
    o : Out(stream.Signature(ByteBeat))
        The same frames in ``r_domain``; ``valid`` rises on a frame's first byte only when the
        whole frame (or a full FIFO) is buffered.
    """

    def __init__(self, *, depth=2048, w_domain="sync", r_domain="gmii_tx"):
        assert depth == 1 << ceil_log2(depth)
        self._depth = depth
        self._w_domain, self._r_domain = w_domain, r_domain
        super().__init__({
            "i": In(stream.Signature(ByteBeat)),
            "o": Out(stream.Signature(ByteBeat)),
        })

    def elaborate(self, platform):
        m = Module()
        w, r = self._w_domain, self._r_domain
        m.submodules.fifo = fifo = AsyncFIFO(width=len(self.i.payload.as_value()), depth=self._depth,
                                             w_domain=w, r_domain=r)
        wiring.connect(m, wiring.flipped(self.i), fifo.w_stream)
        out = fifo.r_stream

        # Complete frames written, and taken; at most ``depth`` frames are ever in flight.
        width = ceil_log2(self._depth) + 2
        m.submodules.written = written = CountSynchronizer(width, i_domain=w, o_domain=r)
        with m.If(self.i.valid & self.i.ready & self.i.payload.last):
            m.d[w] += written.i.eq(written.i + 1)
        taken = Signal(width)
        with m.If(self.o.valid & self.o.ready & self.o.payload.last):
            m.d[r] += taken.eq(taken + 1)

        # Inside a frame already offered: its bytes flow as they come.
        sending = Signal()
        with m.If(self.o.valid & self.o.ready):
            m.d[r] += sending.eq(~self.o.payload.last)

        # (a frame longer than the FIFO goes out before its count crosses: ``taken`` may run ahead
        # of ``written.o`` for a few cycles, so compare the signed difference, not equality)
        ahead = Signal(width)
        m.d.comb += ahead.eq(written.o - taken)
        whole_frame = (ahead != 0) & ~ahead[-1]
        # The FIFO's fill as the read side sees it: bytes written (crossed as a count, late: never
        # more than the fill, and below zero while the bytes read overtake the late count, so
        # signed) less bytes read. Not the FIFO's own ``r_level``, whose Gray decode a synthesis
        # chains through every bit (a dozen LUT levels before the transmit MAC).
        m.submodules.bytes_in = bytes_in = CountSynchronizer(width, i_domain=w, o_domain=r)
        with m.If(self.i.valid & self.i.ready):
            m.d[w] += bytes_in.i.eq(bytes_in.i + 1)
        bytes_out, fill = Signal(width), Signal(width)
        with m.If(out.valid & out.ready):
            m.d[r] += bytes_out.eq(bytes_out + 1)
        m.d.comb += fill.eq(bytes_in.o - bytes_out)
        full = ~fill[-1] & (fill >= self._depth - 1)
        # whether a frame may start, registered: a cycle late it errs only towards waiting, but
        # in the cycle after a frame's last byte, when it still counts that frame (masked)
        offer, ended = Signal(), Signal()
        m.d[r] += [offer.eq(whole_frame | full), ended.eq(self.o.valid & self.o.ready & self.o.payload.last)]
        m.d.comb += [
            self.o.valid.eq(out.valid & (sending | (offer & ~ended))),
            self.o.payload.eq(out.payload),
            out.ready.eq(self.o.ready & self.o.valid),
        ]
        return m
