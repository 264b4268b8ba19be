"""The frame slots' maps: where each row of each slot comes from, and the occupancy map.

Row map: per slot and row, whether the row arrived in that slot (``stored``) and the slot whose
words the row shows (``source``): the slot itself for a whole frame and for a row a delta frame
carries, the delta's base for a row it does not. ``stored`` is read back in ``sync`` (one cycle
later) to refuse a row that arrived before, ``source`` in ``dmd`` by the plane reader, with the
slot's kind (whole or delta). Each half is a memory of its own with one write and one read port,
so that each maps to block RAM: a ``source`` read is then a flip-flop to flip-flop path with no
logic (as one memory with two read ports it took distributed RAM and several LUT levels of
multiplexers); ``stored`` keeps 64 rows a word and picks the row's bit after the read.
Occupancy map: per slot and DMD block, 8 bits, plane ``k`` has a bit set somewhere in the block
(a delta starts from its base's, a superset of what its rows from the base hold: a block it says
has bits is loaded, never wrongly cleared). It is read in ``sync`` by the row ingest (for a
delta's start) and in ``dmd`` by the sequencer, each from a copy of its own in block RAM, so that
neither read has logic between its address registers and its output. Every map is written in
``sync`` through one stream of writes; the ``dmd`` read ports are safe because a slot reaches the
sequencer only after it is complete, and a base is never written while a delta uses it (see
:mod:`gateware.store.layouts`).
"""

from amaranth import Cat, Module, Mux, Signal
from amaranth.lib import data, stream, wiring
from amaranth.lib.memory import Memory
from amaranth.lib.wiring import In, Out
from amaranth.utils import ceil_log2

from .addresses import PLANES
from .layouts import BLOCK_BITS, SLOT_BITS, OccupancySignature

__all__ = ["SlotMaps", "RowLookupSignature", "map_write_layout", "ROW_ANSWERS"]

#: What each read port of the row map answers: whether the row arrived, or where its words are.
ROW_ANSWERS = {"stored": {"stored": 1}, "source": {"source": SLOT_BITS, "delta": 1}}


def map_write_layout(dmd):
    """One write to the maps of slot ``slot``: row ``row``'s entry becomes ``stored`` and
    ``source``; the bits ``occupancy_mask`` of block ``block``'s occupancy take the values of
    ``occupancy``; with ``opening``, the slot's kind becomes ``delta``."""
    return data.StructLayout({
        "slot": SLOT_BITS,
        "row": ceil_log2(dmd.rows),
        "stored": 1,
        "source": SLOT_BITS,
        "block": BLOCK_BITS,
        "occupancy_mask": PLANES,
        "occupancy": PLANES,
        "opening": 1,
        "delta": 1,
    })


class RowLookupSignature(wiring.Signature):
    """A read port of the row map, seen from its user.

    Parameters
    ----------
    dmd : :class:`spec.facts.DmdType`
    answers : str
        A key of :data:`ROW_ANSWERS`: ``"stored"`` (the row ingest's port) or ``"source"`` (the
        plane reader's).

    Members
    -------
    slot, row : Out
        Which row of which slot to look up.
    en : Out(1)
        Look up (high unless driven low); low, the answers keep their values.
    stored : In(1)
        (``"stored"``) One cycle later: that row arrived in that slot.
    source : In(SLOT_BITS)
        (``"source"``) One cycle later: the slot whose words that row shows (of a delta frame;
        a whole frame's rows show the slot itself).
    delta : In(1)
        (``"source"``) One cycle later: the slot holds a delta frame (some rows show its base's
        words).
    """

    def __init__(self, dmd, answers):
        self._row_bits, self._answers = ceil_log2(dmd.rows), answers
        super().__init__({
            "slot": Out(SLOT_BITS),
            "row": Out(self._row_bits),
            "en": Out(1, init=1),
            **{name: In(width) for name, width in ROW_ANSWERS[answers].items()},
        })

    def __eq__(self, other):
        return (isinstance(other, RowLookupSignature) and other._row_bits == self._row_bits
                and other._answers == self._answers)


class SlotMaps(wiring.Component):
    """Row map and occupancy map of the frame slots.

    Parameters
    ----------
    dmd : :class:`spec.facts.DmdType`
    slots : int
        Frame slots.
    live : int
        The slots whose rows may show another slot's words (delta frames: the live slots of
        :class:`~gateware.store.slot_table.SlotTable`); default: every slot.

    Members
    -------
    writes : In(stream.Signature(map_write_layout(dmd), always_ready=True))
        Writes to the maps, one per cycle (``sync``).
    bitmap : In(RowLookupSignature(dmd, "stored"))
        Row map read port (``sync``): whether a row arrived.
    base_occupancy : In(OccupancySignature())
        Occupancy read port (``sync``): a delta's map starts as its base's.
    sources : In(RowLookupSignature(dmd, "source"))
        Row map read port (``dmd``) for the plane reader: where a row's words are.
    occupancy : In(OccupancySignature())
        Occupancy map read port (``dmd``).
    """

    def __init__(self, dmd, *, slots=4, live=None):
        self._dmd, self._slots = dmd, slots
        self._live = slots if live is None else min(live, slots)
        super().__init__({
            "writes": In(stream.Signature(map_write_layout(dmd), always_ready=True)),
            "bitmap": In(RowLookupSignature(dmd, "stored")),
            "base_occupancy": In(OccupancySignature()),
            "sources": In(RowLookupSignature(dmd, "source")),
            "occupancy": In(OccupancySignature()),
        })

    def elaborate(self, platform):
        m = Module()
        row_bits = ceil_log2(self._dmd.rows)
        write = self.writes.payload

        # The stored bits of every slot, 64 rows a word (each row's bit written alone): a memory of
        # a few thousand words, not one per row of every slot (170 XGA slots are 174,080 rows,
        # and the tools choke on as many initial values). The row's bit is picked from its word
        # after the read, in ``sync``.
        slot_bits = ceil_log2(self._slots)
        word_bits = min(6, row_bits)
        m.submodules.stored = stored = Memory(shape=1 << word_bits, depth=self._slots << (row_bits - word_bits),
                                              init=[])
        w, r = stored.write_port(granularity=1), stored.read_port(domain="sync")
        picked = Signal(word_bits)
        m.d.comb += [w.addr.eq(Cat(write.row[word_bits:], write.slot[:slot_bits])),
                     w.data.eq(Cat(write.stored for _ in range(1 << word_bits))),
                     w.en.eq(Mux(self.writes.valid & (write.slot < self._slots), 1 << write.row[:word_bits], 0)),
                     r.addr.eq(Cat(self.bitmap.row[word_bits:], self.bitmap.slot[:slot_bits])),
                     r.en.eq(self.bitmap.en), self.bitmap.stored.eq(r.data.bit_select(picked, 1))]
        with m.If(self.bitmap.en):
            m.d.sync += picked.eq(self.bitmap.row[:word_bits])
        # the sources of the live slots only: a slot beyond them holds a whole frame (never a
        # delta, :mod:`gateware.store.slot_table`), whose rows the plane reader reads from the
        # slot itself without asking for their source
        live_bits = ceil_log2(self._live)
        m.submodules.source = source = Memory(shape=SLOT_BITS, depth=self._live << row_bits, init=[])
        w, r = source.write_port(), source.read_port(domain="dmd")
        m.d.comb += [w.addr.eq(Cat(write.row, write.slot[:live_bits])), w.data.eq(write.source),
                     w.en.eq(self.writes.valid & (write.slot < self._live)),
                     r.addr.eq(Cat(self.sources.row, self.sources.slot[:live_bits])), r.en.eq(self.sources.en),
                     self.sources.source.eq(r.data)]
        m.submodules.kinds = kinds = Memory(shape=1, depth=self._slots, init=[])
        kinds_w, kinds_r = kinds.write_port(), kinds.read_port(domain="dmd")
        m.d.comb += [
            kinds_w.addr.eq(write.slot),
            kinds_w.data.eq(write.delta),
            kinds_w.en.eq(self.writes.valid & write.opening),
            kinds_r.addr.eq(self.sources.slot),
            kinds_r.en.eq(self.sources.en),
            self.sources.delta.eq(kinds_r.data),
        ]

        # a copy of the occupancy map per read port: as one memory with two read ports it took
        # distributed RAM, and the ``dmd`` read was a tree of LUT-RAM outputs and multiplexers
        # 5 LUT levels deep
        for name, port, domain in (("base_occupancy", self.base_occupancy, "sync"),
                                   ("occupancy", self.occupancy, "dmd")):
            m.submodules[name] = occ = Memory(shape=PLANES, depth=self._slots << BLOCK_BITS, init=[],
                                              attrs={"ram_style": "block"})
            occ_w, occ_r = occ.write_port(granularity=1), occ.read_port(domain=domain)
            m.d.comb += [
                occ_w.addr.eq(Cat(write.block, write.slot)),
                occ_w.data.eq(write.occupancy),
                occ_w.en.eq(Cat(self.writes.valid & bit for bit in write.occupancy_mask)),
                occ_r.addr.eq(Cat(port.block, port.slot)),
                port.planes.eq(occ_r.data),
            ]
        return m
