"""The receive buffer: a ring of frames written at line rate, kept or forgotten when they end.

The stack writes every byte of a frame as it arrives and only then learns whether the frame is
good; :meth:`FrameBuffer.commit` keeps it, :meth:`FrameBuffer.discard` rewinds the write pointer
so that nothing of it remains. Kept frames are read back by address and freed in order.
"""

from amaranth import Module, Signal, unsigned
from amaranth.lib import data, stream, wiring
from amaranth.lib.memory import Memory
from amaranth.lib.wiring import In, Out
from amaranth.utils import exact_log2

from .layouts import OFFSET_BITS, BodyByte

__all__ = ["FrameBuffer", "read_request_layout"]


def read_request_layout(depth):
    return data.StructLayout({"addr": exact_log2(depth) + 1, "length": OFFSET_BITS})


class FrameBuffer(wiring.Component):
    """A ring of ``depth`` bytes (a power of 2).

    Pointers are ``log2(depth) + 1`` bits wide: the extra bit tells a full ring from an empty one.

    Members
    -------
    write : In(stream.Signature(8))
        Bytes of the frame being received. Always ready: a byte that finds the ring full is not
        stored and marks the frame as overflowed.
    commit : In(1)
        Keep the frame written since the last commit or discard.
    discard : In(1)
        Forget it.
    overflow : Out(1)
        A byte of the current frame did not fit.
    frame_start : Out(pointer)
        Where the current frame's first byte is.
    write_pointer : Out(pointer)
        One past its last byte.
    read : In(stream.Signature(read_request_layout))
        Read ``length`` (at least 1) bytes from ``addr``; taken when the previous read is done.
    data : Out(stream.Signature(BodyByte))
        The bytes read, ``last`` on the final one.
    release : In(1)
        Free everything up to ``release_to`` (frames are freed in the order they were kept).
        Bytes are also freed as they are read.
    release_to : In(pointer)
    """

    def __init__(self, depth):
        self._depth = depth
        ptr = unsigned(exact_log2(depth) + 1)
        super().__init__({
            "write": In(stream.Signature(8)),
            "commit": In(1),
            "discard": In(1),
            "overflow": Out(1),
            "frame_start": Out(ptr),
            "write_pointer": Out(ptr),
            "read": In(stream.Signature(read_request_layout(depth))),
            "data": Out(stream.Signature(BodyByte)),
            "release": In(1),
            "release_to": In(ptr),
        })

    def elaborate(self, platform):
        m = Module()
        depth = self._depth
        m.submodules.memory = memory = Memory(shape=8, depth=depth, init=[])
        wr_port = memory.write_port()
        rd_port = memory.read_port()

        released = Signal.like(self.release_to)
        used = Signal.like(self.release_to)
        m.d.comb += used.eq(self.write_pointer - released)

        # Write side.
        m.d.comb += [
            self.write.ready.eq(1),
            wr_port.addr.eq(self.write_pointer),
            wr_port.data.eq(self.write.payload),
        ]
        with m.If(self.commit):
            m.d.sync += [self.frame_start.eq(self.write_pointer), self.overflow.eq(0)]
        with m.Elif(self.discard):
            m.d.sync += [self.write_pointer.eq(self.frame_start), self.overflow.eq(0)]
        with m.Elif(self.write.valid):
            with m.If((used == depth) | self.overflow):
                m.d.sync += self.overflow.eq(1)
            with m.Else():
                m.d.comb += wr_port.en.eq(1)
                m.d.sync += self.write_pointer.eq(self.write_pointer + 1)

        # Read side: the port's output register is the stream's payload, so it advances only
        # when the consumer takes a byte (or none is held).
        addr = Signal.like(self.release_to)
        remaining = Signal(OFFSET_BITS)
        busy = Signal()
        advance = ~self.data.valid | self.data.ready
        m.d.comb += [
            self.read.ready.eq(~busy),
            rd_port.addr.eq(addr),
            rd_port.en.eq(busy & advance),
            self.data.payload.data.eq(rd_port.data),
        ]
        with m.If(self.read.valid & self.read.ready):
            m.d.sync += [
                addr.eq(self.read.payload.addr),
                remaining.eq(self.read.payload.length),
                busy.eq(1),
            ]
        # Bytes are freed as they are read, so that a frame being read and the next one being
        # written fit together; ``release`` then frees the rest of the frame (its padding).
        with m.If(self.release):
            m.d.sync += released.eq(self.release_to)
        with m.Elif(rd_port.en):
            m.d.sync += released.eq(addr + 1)
        with m.If(advance):
            m.d.sync += self.data.valid.eq(busy)
            with m.If(busy):
                m.d.sync += [
                    addr.eq(addr + 1),
                    remaining.eq(remaining - 1),
                    self.data.payload.last.eq(remaining == 1),
                    busy.eq(remaining != 1),
                ]
        return m
