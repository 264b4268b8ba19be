"""The states of the sequence slots: the frame slots beyond the live ones, in distributed memory.

The slot table keeps the first slots (the live ones: streaming, delta frames and their bases)
in registers, which it searches every cycle. A stored sequence may span every slot the memory
holds (about 170 XGA frames), and those beyond the live ones are only ever looked up by number
(frame f of a sequence is in slot f), so their states live here, in memories with
combinational read ports (LUT RAM on the Spartan-6, a few LUTs per bit and port).

Two writers change a slot's state: the ingest (it opens a free slot and completes it) and the
table's housekeeping (everything else), possibly on the same cycle but never on the same slot.
The state and the sequence flag are therefore kept as the XOR of two halves, each written by
one writer only: a writer stores the new value XOR the other half, read at its own address
(the classic two-write-port memory built of one-write-port memories). The bit depth is written
by the ingest only, the stale flag by housekeeping only.
"""

from amaranth import Module
from amaranth.lib import data, wiring
from amaranth.lib.memory import Memory
from amaranth.lib.wiring import In, Out

from .layouts import SLOT_BITS

__all__ = ["SlotStates", "SlotView", "ingest_write_layout", "housekeeping_write_layout", "PHASE"]

#: The two-writer half of a slot: its state (a :class:`~gateware.store.slot_table.SlotState`)
#: and whether it belongs to the sequence in force.
PHASE = data.StructLayout({"state": 3, "in_sequence": 1})


class SlotView(wiring.Signature):
    """A read port, seen from its user: ``slot`` in, the slot's fields out on the same cycle.

    Members
    -------
    slot : Out(SLOT_BITS)
    state : In(3)
    in_sequence, stale : In(1)
    depth : In(4)
    """

    def __init__(self):
        super().__init__({"slot": Out(SLOT_BITS), "state": In(3), "in_sequence": In(1), "stale": In(1),
                          "depth": In(4)})

    def __eq__(self, other):
        return isinstance(other, SlotView)


def ingest_write_layout():
    """The ingest's write: slot ``slot`` becomes ``state`` (and ``in_sequence``); its bit depth
    becomes ``depth`` with ``depth_en``."""
    return data.StructLayout({"en": 1, "slot": SLOT_BITS, "phase": PHASE, "depth": 4, "depth_en": 1})


def housekeeping_write_layout():
    """Housekeeping's write, to the slot its own view (``housekeeping``) reads: the slot
    becomes ``phase`` and ``stale``."""
    return data.StructLayout({"en": 1, "phase": PHASE, "stale": 1})


class SlotStates(wiring.Component):
    """States of slots ``0 .. slots - 1`` (the table uses those from its live ones on; ``sync``).

    All zero at reset: every slot free, outside any sequence.

    Parameters
    ----------
    slots : int
    views : tuple of str
        The names of the read ports besides ``housekeeping``.

    Members
    -------
    <view> : In(SlotView()) for each of ``views``
        Read ports.
    housekeeping : In(SlotView())
        Housekeeping's read port; its write goes to the slot it reads.
    ingest_write : In(ingest_write_layout())
    housekeeping_write : In(housekeeping_write_layout())
    """

    def __init__(self, slots, views=()):
        self._slots, self._views = slots, views
        super().__init__({
            **{name: In(SlotView()) for name in (*views, "housekeeping")},
            "ingest_write": In(ingest_write_layout()),
            "housekeeping_write": In(housekeeping_write_layout()),
        })

    def elaborate(self, platform):
        m = Module()
        depth = self._slots
        m.submodules.by_ingest = by_ingest = Memory(shape=PHASE, depth=depth, init=[])
        m.submodules.by_housekeeping = by_hk = Memory(shape=PHASE, depth=depth, init=[])
        m.submodules.depths = depths = Memory(shape=4, depth=depth, init=[])
        m.submodules.stales = stales = Memory(shape=1, depth=depth, init=[])

        ing, hk = self.ingest_write, self.housekeeping_write
        # each writer reads the other's half at its own address
        other_of_ingest = by_hk.read_port(domain="comb")
        w = by_ingest.write_port()
        m.d.comb += [other_of_ingest.addr.eq(ing.slot), w.addr.eq(ing.slot), w.en.eq(ing.en),
                     w.data.eq(ing.phase.as_value() ^ other_of_ingest.data.as_value())]
        w = depths.write_port()
        m.d.comb += [w.addr.eq(ing.slot), w.en.eq(ing.en & ing.depth_en), w.data.eq(ing.depth)]

        for name in (*self._views, "housekeeping"):
            view = getattr(self, name)
            halves = [memory.read_port(domain="comb") for memory in (by_ingest, by_hk)]
            d, s = depths.read_port(domain="comb"), stales.read_port(domain="comb")
            for port in (*halves, d, s):
                m.d.comb += port.addr.eq(view.slot)
            phase = data.View(PHASE, halves[0].data.as_value() ^ halves[1].data.as_value())
            m.d.comb += [view.state.eq(phase.state), view.in_sequence.eq(phase.in_sequence),
                         view.depth.eq(d.data), view.stale.eq(s.data)]
            if name == "housekeeping":
                mine = by_hk.write_port()
                m.d.comb += [mine.addr.eq(view.slot), mine.en.eq(hk.en),
                             mine.data.eq(hk.phase.as_value() ^ halves[0].data.as_value())]
                stale_w = stales.write_port()
                m.d.comb += [stale_w.addr.eq(view.slot), stale_w.en.eq(hk.en), stale_w.data.eq(hk.stale)]
        return m
