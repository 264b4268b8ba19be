"""The sequence's entry table: which stored frame each step of a sequence shows, and how.

A stored sequence plays its slots in order unless the control record names a number of entries:
then it plays entries ``0 .. entries - 1`` of this table, each the frame of a slot (any slot of
the sequence, as often as wanted) with its own least significant plane's time, dark time,
trigger (wait for one, or follow the frame before), camera trigger
(:class:`~gateware.store.layouts.Showing`), and the planes of its frame it shows: ``depth`` of
them below the ``skip`` most significant, as a ``depth``-bit image (the slot table works out
which stored planes those are when the entry plays, :mod:`gateware.store.slot_table`).
The table is written one entry record at a time (:data:`spec.records.ENTRY`) and read by the
slot table at its play position, a cycle ahead (block RAM: 2,048 entries, each any of the slots of
a sequence, so that a sequence of binary patterns plays every plane of the 170 XGA frames the DDR2
holds); what an entry's planes need of its frame is
summed when it is written, so that the slot table only compares when it plays.
"""

from amaranth import Module
from amaranth.lib import data, memory, stream, wiring
from amaranth.lib.wiring import In, Out

from spec.records import ENTRIES, ENTRY

from ..wire import layout
from .layouts import SHOW_BITS, SLOT_BITS

__all__ = ["Entry", "EntryTable", "ENTRY_BITS"]

#: Bits of an entry's index.
ENTRY_BITS = (ENTRIES - 1).bit_length()


class Entry(data.Struct):
    """One step of a sequence: the slot it shows and how (the entry record's fields; ``depth``:
    the planes shown, 0: all below those left out, and with ``skip`` 0 also more than the frame
    has; ``skip``: its frame's most significant planes left out), and for a ``depth`` other than
    0 what its planes need: a frame of ``need`` planes at least, and its lowest stored plane."""
    slot: SLOT_BITS
    lsb: SHOW_BITS
    dark: SHOW_BITS
    follow: 1
    camera_off: 1
    depth: 4
    skip: 3
    need: 4           # skip + depth
    low_plane: 3      # 8 - skip - depth (a frame of depth d is stored in planes 8-d..7)


class EntryTable(wiring.Component):
    """:data:`spec.records.ENTRIES` entries (``sync``).

    Members
    -------
    entry_writes : In(stream.Signature(layout(ENTRY)))
        Checked entry records (:class:`~gateware.protocol.parser.Parser`): each writes its entry.
    index : In(ENTRY_BITS)
        The entry to read ...
    entry : Out(Entry)
        ... the next cycle (block RAM; an entry written on the cycle it is read reads as written,
        and a table written never shows a half-written entry: a write takes one cycle).
    """

    entry_writes: In(stream.Signature(layout(ENTRY)))
    index: In(ENTRY_BITS)
    entry: Out(Entry)

    def elaborate(self, platform):
        m = Module()
        m.submodules.table = table = memory.Memory(shape=Entry, depth=ENTRIES, init=[])
        write = table.write_port()
        read = table.read_port(transparent_for=(write,))
        record = self.entry_writes.payload
        m.d.comb += [
            self.entry_writes.ready.eq(1),
            write.en.eq(self.entry_writes.valid),
            write.addr.eq(record.index),
            *(write.data[name].eq(record[name]) for name, _ in ENTRY if name != "index"),
            write.data.need.eq(record.skip + record.depth),
            write.data.low_plane.eq(8 - record.skip - record.depth),
            read.addr.eq(self.index),
            self.entry.eq(read.data),
        ]
        return m
