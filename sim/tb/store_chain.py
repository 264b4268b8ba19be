"""Test top: the bit-plane serialiser feeding the store, as the system top will wire them."""

from amaranth import Module
from amaranth.lib import stream, wiring
from amaranth.lib.wiring import In, Out

from gateware.bitplane import Serialiser, pixel_layout
from gateware.store import mcb
from gateware.store.layouts import SLOT_BITS, FrameInfo, OccupancySignature, PlaneRequest
from gateware.store.slots import SlotCounters
from gateware.store.store import Store

__all__ = ["StoreChain"]


class StoreChain(wiring.Component):
    """Pixels in (``sync``), the store's sequencer and MCB ports out; see :class:`Store`."""

    def __init__(self, dmd, *, lanes=8, slots=4, frame_bits=16, fifo_depth=256):
        self._args = dmd, lanes, slots, frame_bits, fifo_depth
        super().__init__({
            "pixels": In(stream.Signature(pixel_layout(dmd, lanes, frame_bits))),
            "bit_depth": In(4),
            "sequence_length": In(5),
            "counters": Out(SlotCounters),
            "ask": In(stream.Signature(0)),
            "frames": Out(stream.Signature(FrameInfo)),
            "release": In(stream.Signature(SLOT_BITS)),
            "occupancy": In(OccupancySignature()),
            "requests": In(stream.Signature(PlaneRequest)),
            "planes": Out(stream.Signature(64)),
            "bad_requests": Out(16),
            "mcb_write": Out(mcb.PortSignature()),
            "mcb_read": Out(mcb.PortSignature()),
        })

    def elaborate(self, platform):
        dmd, lanes, slots, frame_bits, fifo_depth = self._args
        m = Module()
        m.submodules.serialiser = ser = Serialiser(dmd, lanes=lanes, frame_bits=frame_bits)
        m.submodules.store = store = Store(dmd, slots=slots, frame_bits=frame_bits, fifo_depth=fifo_depth)
        wiring.connect(m, wiring.flipped(self.pixels), ser.pixels)
        wiring.connect(m, ser.words, store.words)
        wiring.connect(m, ser.rows, store.rows)
        wiring.connect(m, wiring.flipped(self.ask), store.ask)
        wiring.connect(m, store.frames, wiring.flipped(self.frames))
        wiring.connect(m, wiring.flipped(self.release), store.release)
        wiring.connect(m, wiring.flipped(self.occupancy), store.occupancy)
        wiring.connect(m, wiring.flipped(self.requests), store.requests)
        wiring.connect(m, store.planes, wiring.flipped(self.planes))
        wiring.connect(m, store.mcb_write, wiring.flipped(self.mcb_write))
        wiring.connect(m, store.mcb_read, wiring.flipped(self.mcb_read))
        m.d.comb += [
            store.bit_depth.eq(self.bit_depth),
            store.sequence_length.eq(self.sequence_length),
            self.counters.eq(store.counters),
            self.bad_requests.eq(store.bad_requests),
        ]
        return m
