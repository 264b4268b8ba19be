"""Frame slots: which frame goes where in DDR2, when it may be shown, and the occupancy map.

The slot keeper sits between the serialiser and the writer (``sync`` domain). For every row it
decides, at the row's first word, whether the row is stored and in which slot; a refused row is
dropped whole and counted, an accepted one goes to the writer with its slot, so a row can only
ever be written inside the slot chosen here, whatever its header said.

Slot life
---------
``FREE -> RECEIVING -> WRITING -> READY -> SHOWN -> FREE`` (streaming) or ``-> READY`` again
(sequence); a whole frame that a delta frame held uses as its base goes to KEPT instead of FREE
and stays there until no delta uses it. A slot is RECEIVING while rows arrive (the row map says
which), WRITING once every row has arrived until the writer reports the last row in memory,
READY (complete) until the sequencer is given it, SHOWN until the sequencer releases it. Only
RECEIVING slots are written, so a READY, SHOWN or KEPT frame never changes (no tearing).

Streaming mode (``sequence_length`` = 0): one frame receives at a time. A row of a frame id
newer (serial-number order) than the last one started begins a new frame; a receiving frame it
interrupts is abandoned (counted: it was never complete, so never shown). When a frame
completes, an older READY one that was never shown is freed (counted as replaced). A row of an
older frame is refused (counted: stale, or shown if that frame is being shown). At least three
slots: one receiving, one ready, one shown.

Sequence mode (``sequence_length`` = N > 0): frame id f < N goes to slot f; once all N are
complete they are given to the sequencer in order 0, 1, .., N-1, 0, .. and a released slot stays
in the sequence. Changing ``sequence_length`` frees every slot that is not shown. A sequence
spans every slot the memory holds: streaming and delta frames use the first
:data:`~gateware.store.layouts.LIVE_SLOTS`, whose states are searched every cycle; the slots
beyond them hold a sequence's whole frames (a delta frame there is refused as having no base).

Delta frames
------------
A delta frame carries only some rows (``carried`` of them) and names a whole frame held as its
base; it is complete once those rows have arrived, takes its bit depth from the base, and shows
the base's words in every other row (the row map says, per row, which slot the plane reader reads).
A delta whose base is not held is refused row by row (``rows_no_base``).

Occupancy
---------
Per slot and DMD block, 8 bits: plane k has a bit set somewhere in the block (the OR of the
serialiser's row flags). Cleared when a slot is taken for a new frame, written only while the
slot receives; read from the ``dmd`` domain through a second read port of the same memory,
which is safe because a slot reaches the sequencer only after it is complete (see
:mod:`gateware.store.layouts`).
"""

from amaranth import Module
from amaranth.lib import data, wiring
from amaranth.lib.wiring import Out

from ..compose import forward, members
from .entries import EntryTable
from .layouts import BLOCK_BITS, COUNTER_BITS, LIVE_SLOTS, SLOT_BITS
from .row_ingest import RowIngest
from .slot_crossing import SlotCrossing
from .slot_maps import SlotMaps
from .slot_table import SlotState, SlotTable

__all__ = ["FrameSlots", "SlotState", "SlotCounters"]


class SlotCounters(data.Struct):
    """Event counters (``COUNTER_BITS`` wide, wrapping)."""
    frames_complete: COUNTER_BITS     # every row arrived
    frames_replaced: COUNTER_BITS     # complete, freed unshown for a newer one (streaming)
    frames_abandoned: COUNTER_BITS    # receiving, interrupted by a newer frame before it was complete
    rows_outside: COUNTER_BITS        # row number beyond the frame: refused
    rows_stale: COUNTER_BITS          # frame id older than the frame receiving, or not in the sequence
    rows_shown: COUNTER_BITS          # frame id of a slot being shown: refused
    rows_duplicate: COUNTER_BITS      # row already received (overlapping records): refused
    rows_no_slot: COUNTER_BITS        # no slot free (the sequencer holds too many): refused
    rows_no_base: COUNTER_BITS        # a delta frame whose base is not a whole frame held: refused
    bad_releases: COUNTER_BITS        # release of a slot that was not shown
    calibration_losses: COUNTER_BITS  # the memory lost its calibration: every frame forgotten
    frames_lost: COUNTER_BITS         # frames (held or not) forgotten when the memory was lost
    entries_skipped: COUNTER_BITS     # sequence entries skipped: their slot is outside the sequence


class FrameSlots(wiring.Component):
    """Frame slots, row bookkeeping and the occupancy map of the store.

    Five parts: the row ingest (:class:`~gateware.store.row_ingest.RowIngest`) admits or drops each
    row, in the slot the slot table (:class:`~gateware.store.slot_table.SlotTable`) places it in;
    the maps (:class:`~gateware.store.slot_maps.SlotMaps`) hold the row bitmap and the occupancy
    map; the crossing (:class:`~gateware.store.slot_crossing.SlotCrossing`) carries the
    sequencer's asks, releases and answers between ``dmd`` and ``sync``; the entry table
    (:class:`~gateware.store.entries.EntryTable`) holds a sequence's entries.

    Parameters
    ----------
    dmd : :class:`spec.facts.DmdType`
    slots : int
        Frame slots (3 to ``2**SLOT_BITS``): the first :data:`~gateware.store.layouts.LIVE_SLOTS`
        for streaming and delta frames, all of them for a stored sequence.
    live : int
        Slots kept in registers (default :data:`~gateware.store.layouts.LIVE_SLOTS`; fewer in
        tests, to reach the others with small memories).
    frame_bits : int
        Width of the serialiser's frame tag: the frame id of the record (up to 16 bits).

    Members
    -------
    words, rows, store, bit_depth
        The row ingest's (``sync``): the serialiser's words and row flags in, the accepted words
        to the writer out, the bit depth of frames that start from now on.
    written, sequence_length, entries, loop, sequence_start, lose, forgotten
        The slot table's (``sync``): slots the writer has written, the mode, the sequence's
        entries played, and the memory's loss (:mod:`gateware.store.recovery`).
    entry_writes
        The entry table's (``sync``): entry records to write
        (:class:`~gateware.store.entries.EntryTable`).
    counters : Out(SlotCounters)
        (``sync``).
    ask, frames, release
        The crossing's (``dmd``): asks, answers and releases of the sequencer.
    occupancy, sources
        The maps' read ports (``dmd``): occupancy for the sequencer, where each row comes from
        for the plane reader.
    """

    #: The ports each part gives the whole.
    _PORTS = {
        "ingest": ("words", "rows", "store", "bit_depth"),
        "table": ("written", "sequence_length", "entries", "loop", "sequence_start", "lose", "forgotten"),
        "entries": ("entry_writes",),
        "crossing": ("ask", "frames", "release"),
        "maps": ("occupancy", "sources"),
    }

    #: The parts that count events, each some of the counters.
    _COUNTING = ("ingest", "table")

    def __init__(self, dmd, *, slots=4, frame_bits=16, live=LIVE_SLOTS):
        assert 3 <= slots <= 2**SLOT_BITS and dmd.blocks <= 2**BLOCK_BITS and frame_bits <= 16
        assert dmd.rows >= 2**BLOCK_BITS
        self._parts = {
            "ingest": RowIngest(dmd, slots=slots, frame_bits=frame_bits),
            "table": SlotTable(slots=slots, frame_bits=frame_bits, live=live),
            "crossing": SlotCrossing(),
            "maps": SlotMaps(dmd, slots=slots, live=live),
            "entries": EntryTable(),
        }
        ports = {}
        for part, names in self._PORTS.items():
            ports.update(members(self._parts[part], names))
        super().__init__({**ports, "counters": Out(SlotCounters)})
        counted = [name for part in self._COUNTING for name in _counter_names(self._parts[part])]
        assert sorted(counted) == sorted(_counter_names(self)), "each counter is counted by one part"

    def elaborate(self, platform):
        m = Module()
        for name, part in self._parts.items():
            m.submodules[name] = part
            forward(m, self, part, self._PORTS[name])
        ingest, table, maps, crossing = (self._parts[name] for name in ("ingest", "table", "maps", "crossing"))
        wiring.connect(m, ingest.placement, table.placement)
        wiring.connect(m, ingest.opened, table.opened)
        wiring.connect(m, ingest.completed, table.completed)
        wiring.connect(m, ingest.map_writes, maps.writes)
        wiring.connect(m, ingest.bitmap, maps.bitmap)
        wiring.connect(m, ingest.base_occupancy, maps.base_occupancy)
        wiring.connect(m, crossing.asks, table.asks)
        wiring.connect(m, crossing.releases, table.releases)
        wiring.connect(m, table.answers, crossing.answers)
        entries = self._parts["entries"]
        m.d.comb += [entries.index.eq(table.entry_index), table.entry.eq(entries.entry)]
        for part in self._COUNTING:
            counters = self._parts[part].counters
            for name in _counter_names(self._parts[part]):
                m.d.comb += self.counters[name].eq(counters[name])
        return m


def _counter_names(component):
    """The fields of ``component.counters``."""
    return [name for name, _ in data.Layout.cast(component.counters.shape())]
