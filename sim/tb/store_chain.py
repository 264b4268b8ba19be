"""Test top: the bit-plane serialiser feeding the store, as the system top will wire them."""

from amaranth import Module
from amaranth.lib import stream, wiring
from amaranth.lib.wiring import In

from gateware.bitplane import Serialiser
from gateware.compose import forward, members
from gateware.protocol.layouts import pixel_layout
from gateware.store.store import Store

__all__ = ["StoreChain"]

#: The store's ports the serialiser drives; every other port of the store is this top's own.
FED = ("words", "rows")


class StoreChain(wiring.Component):
    """Pixels in (``sync``), the store's sequencer and MCB ports out; see :class:`Store`."""

    def __init__(self, dmd, *, lanes=8, slots=4, frame_bits=16, fifo_depth=256, read_width=128, **store):
        self._serialiser = Serialiser(dmd, lanes=lanes, frame_bits=frame_bits)
        self._store = Store(dmd, slots=slots, frame_bits=frame_bits, fifo_depth=fifo_depth, read_width=read_width,
                            **store)
        super().__init__({"pixels": In(stream.Signature(pixel_layout(dmd, lanes, frame_bits))),
                          **members(self._store, exclude=FED)})

    def elaborate(self, platform):
        m = Module()
        m.submodules.serialiser = ser = self._serialiser
        m.submodules.store = store = self._store
        wiring.connect(m, wiring.flipped(self.pixels), ser.pixels)
        for name in FED:
            wiring.connect(m, getattr(ser, name), getattr(store, name))
        forward(m, self, store)
        return m
