"""The row ingest: each row of the serialiser is stored whole in the slot the table gives it, or
dropped whole and counted (``sync`` domain).

At a row's first word the ingest asks the slot table where the row goes
(:class:`~gateware.store.placement.Placement`). A slot taken for a new frame first has its maps
set up (one row per cycle): no row arrived, each row shown from the slot itself, or for a delta
frame from its base, whose occupancy map it starts from. Then the row's entry is read: a row that
arrived before is refused. An accepted row's words of the stored planes go to the writer
with the slot (so a row can only ever be written inside the slot chosen here, whatever its header
said); with the row's last word come its row flags, which set the row's bit in the bitmap and its
block's planes in the occupancy map. The row that completes the frame (every row, or for a delta the
rows it says it carries) is marked for the writer and reported to the table.
"""

from amaranth import Cat, Const, Module, Mux, Signal
from amaranth.lib import data, stream, wiring
from amaranth.lib.memory import Memory
from amaranth.lib.wiring import In, Out
from amaranth.utils import ceil_log2

from gateware.bitplane.serialiser import row_flags_layout, word_layout

from .addresses import PLANES
from .layouts import BLOCK_BITS, COUNTER_BITS, SLOT_BITS, OccupancySignature
from .placement import Placement, PlacementSignature, opening_layout
from .slot_maps import RowLookupSignature, map_write_layout
from .writer import write_word_layout

__all__ = ["RowIngest", "IngestCounters"]


class IngestCounters(data.Struct):
    """The ingest's counters (``COUNTER_BITS`` wide, wrapping); see
    :class:`~gateware.store.slots.SlotCounters`."""
    frames_complete: COUNTER_BITS
    frames_abandoned: COUNTER_BITS
    rows_outside: COUNTER_BITS
    rows_stale: COUNTER_BITS
    rows_shown: COUNTER_BITS
    rows_duplicate: COUNTER_BITS
    rows_no_slot: COUNTER_BITS
    rows_no_base: COUNTER_BITS


#: The placements that refuse a row, and the counter each one counts.
_REFUSALS = {
    Placement.STALE: "rows_stale",
    Placement.SHOWN: "rows_shown",
    Placement.DUPLICATE: "rows_duplicate",
    Placement.NO_SLOT: "rows_no_slot",
    Placement.NO_BASE: "rows_no_base",
}


class RowIngest(wiring.Component):
    """Admit or drop whole rows of the serialiser's words.

    Parameters
    ----------
    dmd : :class:`spec.facts.DmdType`
    slots : int
        Frame slots.
    frame_bits : int
        Width of the serialiser's frame tag.

    Members
    -------
    words : In(stream.Signature(serialiser.word_layout(dmd, frame_bits)))
        The serialiser's words.
    rows : In(stream.Signature(serialiser.row_flags_layout(dmd, frame_bits)))
        The serialiser's row flags; taken together with the last word of each row.
    store : Out(stream.Signature(writer.write_word_layout(dmd)))
        Accepted words of the stored planes, to the writer.
    bit_depth : In(4)
        Planes to store for frames that start from now on, 1..8 (others mean 8).
    placement : Out(PlacementSignature(frame_bits))
        Where a row goes, from the slot table.
    opened : Out(stream.Signature(opening_layout(frame_bits), always_ready=True))
        A slot taken and cleared for a new frame, to the slot table.
    completed : Out(stream.Signature(SLOT_BITS, always_ready=True))
        The slot whose last missing row has arrived, to the slot table.
    map_writes : Out(stream.Signature(slot_maps.map_write_layout(dmd), always_ready=True))
        Clearing and setting the row bitmap and the occupancy map.
    bitmap : Out(RowLookupSignature(dmd, "stored"))
        Whether a row arrived before.
    base_occupancy : Out(OccupancySignature())
        The occupancy map of a delta's base, copied when the delta's slot is set up.
    counters : Out(IngestCounters)
    """

    def __init__(self, dmd, *, slots=4, frame_bits=16):
        self._dmd, self._slots = dmd, slots
        super().__init__({
            "words": In(stream.Signature(word_layout(dmd, frame_bits))),
            "rows": In(stream.Signature(row_flags_layout(dmd, frame_bits))),
            "store": Out(stream.Signature(write_word_layout(dmd))),
            "bit_depth": In(4),
            "placement": Out(PlacementSignature(frame_bits)),
            "opened": Out(stream.Signature(opening_layout(frame_bits), always_ready=True)),
            "completed": Out(stream.Signature(SLOT_BITS, always_ready=True)),
            "map_writes": Out(stream.Signature(map_write_layout(dmd), always_ready=True)),
            "bitmap": Out(RowLookupSignature(dmd, "stored")),
            "base_occupancy": Out(OccupancySignature()),
            "counters": Out(IngestCounters),
        })

    def elaborate(self, platform):
        m = Module()
        dmd, count = self._dmd, self.counters
        # rows each slot still waits for: several slots of a sequence may receive at once (only
        # the current slot's count is read or written, so a memory: LUT RAM, not a register each)
        m.submodules.missing = missing_rows = Memory(shape=range(dmd.rows + 1), depth=self._slots, init=[])
        missing_w, missing_r = missing_rows.write_port(), missing_rows.read_port(domain="comb")
        missing = missing_r.data
        head = self.words.payload
        place = self.placement
        is_last = (head.plane == PLANES - 1) & (head.word == dmd.words_per_row - 1)
        cur_slot = Signal(SLOT_BITS)
        cur_depth = Signal(4)
        delta = Signal()                        # the frame being set up is a delta ...
        base = Signal(SLOT_BITS)                # ... of the frame in this slot,
        base_depth = Signal(4)                  # at its bit depth
        needed = Signal(range(dmd.rows + 1))    # rows that complete it
        clear_index = Signal(ceil_log2(dmd.rows))
        m.d.comb += [missing_r.addr.eq(cur_slot), missing_w.addr.eq(cur_slot)]
        depth_in = self._depth_in(m)
        stored_mask = Signal(PLANES)            # planes a frame of depth cur_depth stores
        m.d.comb += [
            stored_mask.eq(Const(0xFF00, 2 * PLANES) >> cur_depth),
            place.frame.eq(head.frame),
            place.base.eq(head.base),
            place.delta.eq(head.carried != 0),
            self.bitmap.slot.eq(cur_slot),
            self.bitmap.row.eq(head.row),
            self.opened.payload.slot.eq(cur_slot),
            self.opened.payload.frame.eq(head.frame),
            self.opened.payload.depth.eq(Mux(delta, base_depth, depth_in)),
            self.opened.payload.delta.eq(delta),
            self.opened.payload.base.eq(base),
            self.completed.payload.eq(cur_slot),
            self.map_writes.payload.slot.eq(cur_slot),
            self.base_occupancy.slot.eq(place.base_slot),   # block 0, read as the slot is taken
        ]

        def take(*, abandon=False):
            m.d.sync += [cur_slot.eq(place.slot), clear_index.eq(0), delta.eq(head.carried != 0),
                         base.eq(place.base_slot), base_depth.eq(place.base_depth),
                         needed.eq(Mux(head.carried != 0, head.carried, dmd.rows))]
            if abandon:
                m.d.sync += count.frames_abandoned.eq(count.frames_abandoned + 1)
            m.next = "CLEAR"

        def refuse(counter):
            m.d.sync += counter.eq(counter + 1)
            m.next = "DROP"

        self._store_word(m, slot=cur_slot, last=is_last, completes=missing == 1)

        with m.FSM(name="ingest") as ingest:
            m.d.comb += place.between_rows.eq(ingest.ongoing("ROW_START"))
            with m.State("ROW_START"):
                with m.If(self.words.valid & (place.verdict != Placement.HOLD)):
                    with m.If((head.row >= dmd.rows) | (head.carried > dmd.rows)):
                        refuse(count.rows_outside)
                    with m.Elif(place.verdict == Placement.JOIN):
                        m.d.sync += [cur_slot.eq(place.slot), cur_depth.eq(place.depth)]
                        m.next = "LOOKUP"
                    with m.Elif(place.verdict == Placement.TAKE):
                        take()
                    with m.Elif(place.verdict == Placement.ABANDON):
                        take(abandon=True)
                    for verdict, name in _REFUSALS.items():
                        with m.Elif(place.verdict == verdict):
                            refuse(count[name])
                    # WAIT: a slot frees when the frame being written becomes ready

            with m.State("CLEAR"):
                self._clear_row(m, clear_index, slot=cur_slot, delta=delta, base=base)
                m.d.sync += clear_index.eq(clear_index + 1)
                with m.If(clear_index == dmd.rows - 1):
                    m.d.comb += self.opened.valid.eq(1)
                    m.d.comb += [missing_w.en.eq(1), missing_w.data.eq(needed)]
                    m.d.sync += cur_depth.eq(Mux(delta, base_depth, depth_in))
                    m.next = "LOOKUP"

            with m.State("LOOKUP"):
                m.next = "DECIDE"                           # the bitmap bit of the row is read

            with m.State("DECIDE"):
                with m.If(self.bitmap.stored):
                    refuse(count.rows_duplicate)
                with m.Else():
                    m.next = "PASS"

            with m.State("DROP"):
                with m.If(is_last):
                    m.d.comb += [self.words.ready.eq(self.rows.valid), self.rows.ready.eq(self.words.valid)]
                    with m.If(self.words.valid & self.rows.valid):
                        m.next = "ROW_START"
                with m.Else():
                    m.d.comb += self.words.ready.eq(1)

            with m.State("PASS"):
                with m.If(is_last):
                    both = self.words.valid & self.rows.valid
                    m.d.comb += [
                        self.store.valid.eq(both),
                        self.words.ready.eq(self.store.ready & self.rows.valid),
                        self.rows.ready.eq(self.store.ready & self.words.valid),
                    ]
                    with m.If(both & self.store.ready):
                        self._row_arrived(m, slot=cur_slot, stored_mask=stored_mask)
                        m.d.comb += [missing_w.en.eq(1), missing_w.data.eq(missing - 1)]
                        with m.If(missing == 1):
                            m.d.comb += self.completed.valid.eq(1)
                            m.d.sync += count.frames_complete.eq(count.frames_complete + 1)
                        m.next = "ROW_START"
                with m.Elif(head.plane + cur_depth >= PLANES):
                    m.d.comb += [self.store.valid.eq(self.words.valid), self.words.ready.eq(self.store.ready)]
                with m.Else():
                    m.d.comb += self.words.ready.eq(1)  # a plane below the frame's bit depth
        return m

    def _depth_in(self, m):
        """The bit depth of frames that start now: ``bit_depth``, or 8 for a value outside 1..8."""
        depth = Signal(4, name="depth_in")
        m.d.comb += depth.eq(self.bit_depth)
        with m.If((self.bit_depth == 0) | (self.bit_depth > PLANES)):
            m.d.comb += depth.eq(PLANES)
        return depth

    def _store_word(self, m, *, slot, last, completes):
        """The writer's word is the head word in the slot chosen here, whatever the row's header
        said; ``last`` on the row's last word, ``completes`` when that row completes its frame."""
        head, word = self.words.payload, self.store.payload
        m.d.comb += [
            word.data.eq(head.data),
            word.slot.eq(slot),
            word.plane.eq(head.plane),
            word.row.eq(head.row),
            word.word.eq(head.word),
            word.last.eq(last),
            word.completes.eq(completes),
        ]

    def _clear_row(self, m, index, *, slot, delta, base):
        """Set row ``index`` of a slot taken for a new frame: no row arrived, the row shown from the
        slot itself (a delta's from its base), and block ``index``'s occupancy cleared (a delta's
        copied from its base)."""
        writes = self.map_writes.payload
        m.d.comb += [
            # the base's occupancy of block i is read while block i - 1 is written
            self.base_occupancy.slot.eq(base),
            self.base_occupancy.block.eq(index[:BLOCK_BITS] + 1),
            self.map_writes.valid.eq(1),
            writes.row.eq(index),
            writes.source.eq(Mux(delta, base, slot)),
            writes.block.eq(index[:BLOCK_BITS]),
            writes.occupancy_mask.eq(Cat((index < 2**BLOCK_BITS) for _ in range(PLANES))),
            writes.occupancy.eq(Mux(delta, self.base_occupancy.planes, 0)),
            writes.opening.eq(index == 0),
            writes.delta.eq(delta),
        ]

    def _row_arrived(self, m, *, slot, stored_mask):
        """Record an accepted row as it ends: its bit in the bitmap, its source its own slot, and
        the planes of ``stored_mask`` its block has set in the occupancy map."""
        flags, writes = self.rows.payload, self.map_writes.payload
        m.d.comb += [
            self.map_writes.valid.eq(1),
            writes.row.eq(self.words.payload.row),
            writes.stored.eq(1),
            writes.source.eq(slot),
            writes.block.eq(flags.block),
            writes.occupancy_mask.eq(flags.planes & stored_mask),
            writes.occupancy.eq(~0),
        ]
