"""Test fixture: a store stand-in that answers the sequencer's plane requests.

Not the product's reader: the store's ports as the sequencer sees them
(:mod:`gateware.store.layouts`) in front of three tables: the planes' words, the occupancy map
and the frames to offer (:func:`contents` fills them from images and a frame list). The tables
are read ports (:class:`TableSignature`) outside :class:`SourcedSequencer`, so that the same
sequencer and store stand-in run in the Amaranth simulator with the tables in memories
(:class:`SequencerBench`) and under Verilator with the tables loaded from files at run time
(:class:`sim.rigs.seq_rig.SequencerRig`).
"""

from dataclasses import dataclass

import numpy as np
from amaranth import Module, Signal, Value
from amaranth.lib import data, memory, stream, wiring
from amaranth.lib.wiring import In, Out
from amaranth.utils import ceil_log2

from gateware.compose import forward, members
from gateware.dlpc410.sequencer import Sequencer
from gateware.store.layouts import SLOT_BITS, FrameInfo, PlaneRequest, Showing
from sim.models import bitplane_model as bitplane
from spec.registers import TIME_BITS

__all__ = ["TableSignature", "OfferedFrame", "Contents", "contents", "PlaneSource", "SourcedSequencer",
           "SequencerBench", "ramp_image", "table_members", "table_depths", "SLOTS", "MAX_FRAMES",
           "TABLES"]

#: Slots the plane table holds.
SLOTS = 2
#: Entries of the frame table.
MAX_FRAMES = 16
#: The tables behind the store stand-in, by member name.
TABLES = ("planes", "occupancy_map", "offered")
#: The sequencer's members that face the store.
_STORE_SIDE = ("frames", "requests", "words", "occ_slot", "occupancy")


def ramp_image(dmd, slot):
    """The image of ``slot`` when a run gives none: every grey level on every row."""
    r = np.arange(dmd.rows)[:, None]
    c = np.arange(dmd.columns)[None, :]
    return ((c + r + 37 * slot) & 255).astype(np.uint8)


class TableSignature(wiring.Signature):
    """An asynchronous read port, seen from its reader: ``addr`` out, ``data`` in."""

    def __init__(self, addr_bits, shape):
        super().__init__({"addr": Out(addr_bits), "data": In(shape)})


class OfferedFrame(data.Struct):
    """An entry of the frame table: offer a frame of ``bit_depth`` planes in ``slot`` from stored
    plane ``low_plane`` up once the sequencer's time base reaches ``ready`` (``sequence``: as the
    next frame of a stored sequence), shown as ``showing`` says; entries after the last have
    ``valid`` low."""
    valid: 1
    slot: SLOT_BITS
    bit_depth: 4
    ready: TIME_BITS
    sequence: 1
    showing: Showing
    low_plane: 3


@dataclass
class Contents:
    """The three tables: ``planes`` (uint64 words, slot-major, then plane, row, word),
    ``occupancy`` (per slot the blocks' bytes packed, block 0 lowest) and ``offered`` (packed
    :class:`OfferedFrame`)."""
    planes: np.ndarray
    occupancy: list
    offered: list


def contents(dmd, frames, images=None, store_words=1):
    """The tables for ``frames`` (list of (slot, bit depth), (slot, bit depth, ready), (slot,
    bit depth, ready, sequence), (slot, bit depth, ready, sequence, showing): ``showing`` a
    dict of :class:`~gateware.store.layouts.Showing`'s fields, or (slot, bit depth, ready,
    sequence, showing, skip): the frame shows the stored planes ``8 - depth - skip .. 7 - skip``
    as a sequence entry with that skip does) and
    ``images`` ({slot: 8-bit image}; None: :func:`ramp_image` in every slot with every block
    marked occupied, whatever the image holds); the planes ``store_words`` words an entry."""
    assert len(frames) <= MAX_FRAMES, f"at most {MAX_FRAMES} frames"
    planes = np.zeros((SLOTS, 8, dmd.rows, dmd.words_per_row), dtype=np.uint64)
    occupancy = [[0] * dmd.blocks for _ in range(1 << SLOT_BITS)]
    given = {s: ramp_image(dmd, s) for s in range(SLOTS)} if images is None else images
    assert all(0 <= slot < SLOTS for slot in given), f"images for slots 0..{SLOTS - 1} only"
    for slot, image in given.items():
        planes[slot] = bitplane.plane_words(image)
        occupancy[slot] = [255] * dmd.blocks if images is None else \
            [int(x) for x in bitplane.occupancy(image, dmd.rows_per_block)]
    offered = [OfferedFrame.const({"valid": 1, "slot": f[0], "bit_depth": f[1], "ready": f[2] if len(f) > 2 else 0,
                                   "sequence": f[3] if len(f) > 3 else 0,
                                   "showing": f[4] if len(f) > 4 else {},
                                   "low_plane": (8 - f[1] - (f[5] if len(f) > 5 else 0)) & 7}).as_value().value
               for f in frames]
    words = planes.ravel()
    if store_words > 1:
        words = [sum(int(w) << (64 * i) for i, w in enumerate(words[k:k + store_words]))
                 for k in range(0, len(words), store_words)]
    return Contents(words, [sum(v << (8 * b) for b, v in enumerate(row)) for row in occupancy], offered)


class PlaneSource(wiring.Component):
    """Answers :class:`PlaneRequest` with words, ``store_words`` per transfer and a transfer a
    cycle; offers the frame table's frames in turn.

    A frame is offered once ``now`` (the sequencer's time base) has reached its ``ready``,
    after the frames before it were taken or dropped.

    Members
    -------
    requests : In(stream.Signature(PlaneRequest)); words : Out(stream.Signature(64 * store_words))
    frames : Out(stream.Signature(FrameInfo)); ``frame_id`` is the table index
    occ_slot : In(4); occupancy : Out(ArrayLayout(8, blocks))
        The slot's occupancy, one cycle later.
    now : In(TIME_BITS)
    planes, occupancy_map, offered : Out(TableSignature)
        The tables (:class:`Contents`), read asynchronously.
    """

    def __init__(self, dmd, store_words=1):
        self._dmd, self._store_words = dmd, store_words
        super().__init__({
            "requests": In(stream.Signature(PlaneRequest)),
            "words": Out(stream.Signature(64 * store_words)),
            "frames": Out(stream.Signature(FrameInfo)),
            "occ_slot": In(SLOT_BITS),
            "occupancy": Out(data.ArrayLayout(8, dmd.blocks)),
            "now": In(TIME_BITS),
            **table_members(dmd, store_words),
        })

    def elaborate(self, platform):
        m = Module()
        dmd = self._dmd
        wpr = dmd.words_per_row // self._store_words       # transfers per row
        req = Signal(PlaneRequest)
        busy = Signal()
        word = Signal(range(wpr))
        rows_left = Signal(12)
        with m.If(~busy):
            m.d.comb += self.requests.ready.eq(1)
            with m.If(self.requests.valid):
                m.d.sync += [req.eq(self.requests.payload), busy.eq(1), word.eq(0),
                             rows_left.eq(self.requests.payload.row_count)]
        with m.Else():
            m.d.comb += self.words.valid.eq(1)
            with m.If(self.words.ready):
                m.d.sync += word.eq(word + 1)
                with m.If(word == wpr - 1):
                    m.d.sync += [word.eq(0), req.first_row.eq(req.first_row + 1),
                                 rows_left.eq(rows_left - 1)]
                    with m.If(rows_left == 1):
                        m.d.sync += busy.eq(0)
        m.d.comb += [self.planes.addr.eq(((req.slot * 8 + req.plane) * dmd.rows + req.first_row) * wpr + word),
                     self.words.payload.eq(self.planes.data),
                     self.occupancy_map.addr.eq(self.occ_slot)]
        m.d.sync += self.occupancy.as_value().eq(self.occupancy_map.data)

        index = Signal(range(MAX_FRAMES + 1))
        entry = self.offered.data
        m.d.comb += [self.offered.addr.eq(index),
                     self.frames.valid.eq((index < MAX_FRAMES) & entry.valid & (self.now >= entry.ready)),
                     self.frames.payload.slot.eq(entry.slot), self.frames.payload.bit_depth.eq(entry.bit_depth),
                     self.frames.payload.sequence.eq(entry.sequence),
                     self.frames.payload.showing.eq(entry.showing),
                     self.frames.payload.low_plane.eq(entry.low_plane),
                     self.frames.payload.frame_id.eq(index)]
        with m.If(self.frames.valid & self.frames.ready):
            m.d.sync += index.eq(index + 1)
        return m


def table_depths(dmd, store_words=1):
    """Entries of each table: the planes of :data:`SLOTS` slots (``store_words`` words an
    entry), the occupancy of every slot, and :data:`MAX_FRAMES` frames."""
    return {"planes": SLOTS * 8 * dmd.rows * dmd.words_per_row // store_words, "occupancy_map": 1 << SLOT_BITS,
            "offered": MAX_FRAMES}


def table_members(dmd, store_words=1):
    """The three table ports of :class:`PlaneSource` (the frame index counts one past the last
    entry)."""
    depths = table_depths(dmd, store_words)
    return {
        "planes": Out(TableSignature(ceil_log2(depths["planes"]), 64 * store_words)),
        "occupancy_map": Out(TableSignature(SLOT_BITS, 8 * dmd.blocks)),
        "offered": Out(TableSignature(ceil_log2(depths["offered"] + 1), OfferedFrame)),
    }


class SourcedSequencer(wiring.Component):
    """The sequencer with a :class:`PlaneSource` in front of it; the tables are outside.

    Parameters
    ----------
    dmd : DmdType
    beats, store_words : int
        As :class:`gateware.dlpc410.sequencer.Sequencer`'s.

    Members
    -------
    The sequencer's (:class:`gateware.dlpc410.sequencer.Sequencer`) but those facing the store,
    and the :class:`PlaneSource`'s tables.
    """

    def __init__(self, dmd, *, beats=1, store_words=1):
        self._seq = Sequencer(dmd, beats=beats, store_words=store_words)
        self._src = PlaneSource(dmd, store_words)
        super().__init__({**members(self._seq, exclude=_STORE_SIDE), **members(self._src, TABLES)})

    def elaborate(self, platform):
        m = Module()
        m.submodules.seq = seq = self._seq
        m.submodules.src = src = self._src
        wiring.connect(m, seq.requests, src.requests)
        wiring.connect(m, src.words, seq.words)
        wiring.connect(m, src.frames, seq.frames)
        m.d.comb += [src.occ_slot.eq(seq.occ_slot), seq.occupancy.eq(src.occupancy),
                     src.now.eq(seq.status.now)]
        forward(m, self, seq)
        forward(m, self, src, TABLES)
        return m


class SequencerBench(wiring.Component):
    """The sequencer with its store stand-in, the tables in memories filled from ``frames`` and
    ``images`` (as :func:`contents`): what the Amaranth-simulator tests drive.

    Members
    -------
    As :class:`SourcedSequencer`'s, without the tables.
    """

    def __init__(self, dmd, frames, images=None, *, beats=1, store_words=1):
        self._dmd, self._store_words = dmd, store_words
        self._core = SourcedSequencer(dmd, beats=beats, store_words=store_words)
        self._contents = contents(dmd, frames, images, store_words)
        super().__init__(members(self._core, exclude=TABLES))

    def elaborate(self, platform):
        m = Module()
        m.submodules.core = core = self._core
        forward(m, self, core)
        c = self._contents
        init = {"planes": [int(x) for x in c.planes], "occupancy_map": c.occupancy, "offered": c.offered}
        for name, depth in table_depths(self._dmd, self._store_words).items():
            port = getattr(core, name)
            m.submodules[name] = mem = memory.Memory(shape=len(Value.cast(port.data)), depth=depth,
                                                     init=init[name])
            read = mem.read_port(domain="comb")
            m.d.comb += [read.addr.eq(port.addr), port.data.eq(read.data)]
        return m
