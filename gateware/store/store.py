"""The bit-plane store as one block: frame slots, DDR2 writer and plane reader.

Serialiser words in (``sync``), planes out to the sequencer (``dmd``), two MCB ports to the
memory controller (port 0 in ``sync`` for writing, port 1 in ``dmd`` for reading). The system
top connects ``mcb_write`` and ``mcb_read`` to :class:`gateware.platform.mcb_instance.McbInstance`;
simulations connect them to :mod:`sim.models.mcb`.
"""

from amaranth import Module
from amaranth.lib import stream, wiring
from amaranth.lib.wiring import In, Out

from gateware.bitplane.serialiser import row_flags_layout, word_layout

from . import mcb
from .layouts import SLOT_BITS, FrameInfo, OccupancySignature, PlaneRequest
from .reader import Reader
from .slots import FrameSlots, SlotCounters
from .writer import Writer

__all__ = ["Store"]


class Store(wiring.Component):
    """Frame slots in DDR2 with their writer and reader.

    Parameters
    ----------
    dmd : :class:`spec.facts.DmdType`
    slots : int
        Frame slots (3..16).
    frame_bits : int
        Width of the serialiser's frame tag (the frame id).
    fifo_depth : int
        The reader's look-ahead in words.

    Members
    -------
    words, rows : In(stream)
        From the serialiser (``sync``); see :class:`gateware.store.slots.FrameSlots`.
    bit_depth, sequence_length : In
        Control (``sync``).
    counters : Out(SlotCounters)
        (``sync``).
    ask, frames, release, occupancy : ports of :class:`~gateware.store.slots.FrameSlots` (``dmd``).
    requests : In(stream.Signature(PlaneRequest))
        Plane reads (``dmd``).
    planes : Out(stream.Signature(64))
        The words read (``dmd``).
    bad_requests : Out(16)
        (``dmd``).
    mcb_write : Out(mcb.PortSignature())
        MCB port 0 (``sync``).
    mcb_read : Out(mcb.PortSignature())
        MCB port 1 (``dmd``).
    """

    def __init__(self, dmd, *, slots=4, frame_bits=16, fifo_depth=256):
        self._dmd, self._slots, self._frame_bits, self._fifo_depth = dmd, slots, frame_bits, fifo_depth
        super().__init__({
            "words": In(stream.Signature(word_layout(dmd, frame_bits))),
            "rows": In(stream.Signature(row_flags_layout(dmd, frame_bits))),
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
        m = Module()
        m.submodules.slots = slots = FrameSlots(self._dmd, slots=self._slots, frame_bits=self._frame_bits)
        m.submodules.writer = writer = Writer(self._dmd, slots=self._slots)
        m.submodules.reader = reader = Reader(self._dmd, slots=self._slots, fifo_depth=self._fifo_depth)

        wiring.connect(m, wiring.flipped(self.words), slots.words)
        wiring.connect(m, wiring.flipped(self.rows), slots.rows)
        wiring.connect(m, slots.store, writer.words)
        wiring.connect(m, writer.written, slots.written)
        wiring.connect(m, wiring.flipped(self.ask), slots.ask)
        wiring.connect(m, slots.frames, wiring.flipped(self.frames))
        wiring.connect(m, wiring.flipped(self.release), slots.release)
        wiring.connect(m, wiring.flipped(self.occupancy), slots.occupancy)
        wiring.connect(m, wiring.flipped(self.requests), reader.requests)
        wiring.connect(m, reader.words, wiring.flipped(self.planes))
        wiring.connect(m, writer.mcb, wiring.flipped(self.mcb_write))
        wiring.connect(m, reader.mcb, wiring.flipped(self.mcb_read))
        m.d.comb += [
            slots.bit_depth.eq(self.bit_depth),
            slots.sequence_length.eq(self.sequence_length),
            self.counters.eq(slots.counters),
            self.bad_requests.eq(reader.bad_requests),
        ]
        return m
