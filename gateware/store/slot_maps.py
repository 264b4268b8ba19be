"""The frame slots' two maps: which rows of each slot have arrived, and the occupancy map.

Row bitmap: one bit per slot and row, set when the row is stored; read back (one cycle later) to
refuse a row that arrived before. Occupancy map: per slot and DMD block, 8 bits, plane ``k`` has
a bit set somewhere in the block. Both are written in ``sync`` through one stream of writes; the
occupancy map has a second read port in ``dmd`` for the sequencer, safe because a slot reaches
the sequencer only after it is complete (see :mod:`gateware.store.layouts`).
"""

from amaranth import Cat, Module, Mux
from amaranth.lib import data, stream, wiring
from amaranth.lib.memory import Memory
from amaranth.lib.wiring import In, Out
from amaranth.utils import ceil_log2

from .addresses import PLANES
from .layouts import BLOCK_BITS, SLOT_BITS, OccupancySignature

__all__ = ["SlotMaps", "RowLookupSignature", "map_write_layout"]


def map_write_layout(dmd):
    """One write to both maps of slot ``slot``: bit ``row`` of the row bitmap and the bits
    ``planes`` of block ``block`` of the occupancy map all become ``set``."""
    return data.StructLayout({
        "slot": SLOT_BITS,
        "row": ceil_log2(dmd.rows),
        "block": BLOCK_BITS,
        "planes": PLANES,
        "set": 1,
    })


class RowLookupSignature(wiring.Signature):
    """Read port of the row bitmap, seen from its user (``sync``).

    Members
    -------
    slot, row : Out
        Which row of which slot to look up.
    stored : In(1)
        One cycle later: that row is stored.
    """

    def __init__(self, dmd):
        self._row_bits = ceil_log2(dmd.rows)
        super().__init__({
            "slot": Out(SLOT_BITS),
            "row": Out(self._row_bits),
            "stored": In(1),
        })

    def __eq__(self, other):
        return isinstance(other, RowLookupSignature) and other._row_bits == self._row_bits


class SlotMaps(wiring.Component):
    """Row bitmap and occupancy map of the frame slots.

    Parameters
    ----------
    dmd : :class:`spec.facts.DmdType`
    slots : int
        Frame slots.

    Members
    -------
    writes : In(stream.Signature(map_write_layout(dmd), always_ready=True))
        Writes to both maps, one per cycle (``sync``).
    bitmap : In(RowLookupSignature(dmd))
        Row bitmap read port (``sync``).
    occupancy : In(OccupancySignature())
        Occupancy map read port (``dmd``).
    """

    def __init__(self, dmd, *, slots=4):
        self._dmd, self._slots = dmd, slots
        super().__init__({
            "writes": In(stream.Signature(map_write_layout(dmd), always_ready=True)),
            "bitmap": In(RowLookupSignature(dmd)),
            "occupancy": In(OccupancySignature()),
        })

    def elaborate(self, platform):
        m = Module()
        row_bits = ceil_log2(self._dmd.rows)
        write = self.writes.payload

        m.submodules.bitmap = bitmap = Memory(shape=1, depth=self._slots << row_bits, init=[])
        bitmap_w = bitmap.write_port()
        bitmap_r = bitmap.read_port()
        m.d.comb += [
            bitmap_w.addr.eq(Cat(write.row, write.slot)),
            bitmap_w.data.eq(write.set),
            bitmap_w.en.eq(self.writes.valid),
            bitmap_r.addr.eq(Cat(self.bitmap.row, self.bitmap.slot)),
            self.bitmap.stored.eq(bitmap_r.data),
        ]

        m.submodules.occupancy = occ = Memory(shape=PLANES, depth=self._slots << BLOCK_BITS, init=[])
        occ_w = occ.write_port(granularity=1)
        occ_r = occ.read_port(domain="dmd")
        m.d.comb += [
            occ_w.addr.eq(Cat(write.block, write.slot)),
            occ_w.data.eq(Mux(write.set, ~0, 0)),
            occ_w.en.eq(Mux(self.writes.valid, write.planes, 0)),
            occ_r.addr.eq(Cat(self.occupancy.block, self.occupancy.slot)),
            self.occupancy.planes.eq(occ_r.data),
        ]
        return m
