"""The store's promises as formal properties: where it writes, and which frames it gives out.

The top is :class:`gateware.store.Store` (frame slots, writer, reader) on a DMD of four rows of
one word (:data:`DMD`; DMD block numbers of 2 bits while it is built), three slots and 2-bit
frame ids, with its ``dmd`` side renamed into ``sync`` (one clock: the properties are about
order, not clock ratios; the crossing's own stream rules are checked with free clocks in
:mod:`sim.formal.block_properties`). Everything at its boundary is free (the serialiser's words and row
flags, the sequencer's asks and releases) but for the stream rules, a bit depth held from the
start (any of 1 to 8), and the serialiser's framing: the words of a row share its frame and row,
their planes rise, every stored plane is there and plane 7 ends the row (planes below the bit
depth may be left out, which makes rows short and traces shallow; the pixel data are zero). The
writer's MCB port is :class:`sim.formal.mcb_properties.WritePortEnvelope`, whose ``executed`` bursts are
what reaches the memory. The mode is held: streaming (``sequence_length`` 0) or sequence (1 to
3, fixed).

Properties (white box: the slot events are the parts' own ports):

* every write burst lies inside one slot of the store;
* a word leaves the row ingest for the slot last opened for its frame;
* memory is written only where a word was admitted: for a watched place (slot, plane, row,
  chosen by the solver) the bursts covering it never outnumber the words admitted for it;
* a slot given to the sequencer (answered) is not written until it is opened for a new frame:
  a shown slot's memory is never written;
* a frame is given to the sequencer only when it is complete in memory: at an answer for the
  watched slot, the watched row has arrived whole since the slot was opened, and every word
  admitted for the watched place has been written;
* and the MCB port rules the envelope asserts.
"""

import dataclasses
from contextlib import contextmanager

from amaranth import Array, DomainRenamer, Mux, Signal
from amaranth.asserts import AnyConst
from amaranth.hdl import Assert, Assume, Cover, Fragment
from amaranth.lib import wiring

from gateware.store.addresses import PLANES, AddressMap

from .geometry import FORMAL_DMD
from .harness import Check, FormalTop
from .mcb_properties import WritePortEnvelope
from .stream_properties import stream_rules

__all__ = ["store_checks", "SLOTS"]

SLOTS = 3


#: Four rows: a frame is complete within a few dozen cycles, so that the solver sees frames given
#: out, shown, released and their slots reused.
DMD = dataclasses.replace(FORMAL_DMD, name="formal 64x4", rows=4, blocks=2, rows_per_block=2)


@contextmanager
def _short_blocks(bits=2):
    """The store's DMD block numbers in ``bits`` bits instead of 4 while it is built: the frame
    slots take no fewer rows than there are block numbers (they clear the occupancy map one
    block per row), and no property here depends on the occupancy map."""
    from gateware.store import layouts, row_ingest, slot_maps, slots
    modules = (layouts, row_ingest, slot_maps, slots)
    saved = [module.BLOCK_BITS for module in modules]
    for module in modules:
        module.BLOCK_BITS = bits
    try:
        yield
    finally:
        for module, value in zip(modules, saved, strict=True):
            module.BLOCK_BITS = value


def _properties(store, mode):
    ingest = store._slots._parts["ingest"]
    table = store._slots._parts["table"]
    amap = AddressMap(DMD, SLOTS)

    def prop(m, top):
        m.submodules.memory = port = WritePortEnvelope()
        wiring.connect(m, top.dut.mcb_write, port.port)

        # -- the bit depth, held; the serialiser's framing: the words of a row share its frame
        # and row, their planes rise, every stored plane (from 8 - depth) is there and plane 7
        # ends the row (planes below the depth may be left out: short rows, shallow traces)
        depth = AnyConst(4)
        m.d.comb += [Assume((depth != 0) & (depth <= PLANES)), Assume(store.bit_depth == depth)]
        lowest = PLANES - depth
        words = top.dut.words
        head = words.payload
        last = Signal.like(head.as_value())
        in_row = Signal()
        with m.If(words.valid & words.ready):
            m.d.sync += [last.eq(head.as_value()), in_row.eq(head.plane != PLANES - 1)]
        previous = head.shape()(last)
        # the pixels themselves play no part in where words go: zero, for a lighter model
        m.d.comb += [Assume(head.word == 0), Assume(head.data == 0)]
        with m.If(words.valid & ~in_row):
            m.d.comb += Assume(head.plane <= lowest)
        with m.If(words.valid & in_row):
            following = previous.plane + 1
            m.d.comb += Assume((head.frame == previous.frame) & (head.row == previous.row)
                               & (head.plane > previous.plane)
                               & (head.plane <= Mux(following < lowest, lowest, following)))

        # -- the mode, held
        if mode == "streaming":
            m.d.comb += Assume(store.sequence_length == 0)
        else:
            length = AnyConst(2)
            m.d.comb += [Assume(length != 0), Assume(store.sequence_length == length)]

        # -- events
        burst = port.executed
        first, end = burst.addr, burst.addr + burst.words * top.dut.mcb_write.signature.word_bytes
        opened = ingest.opened
        admitted = ingest.store.valid & ingest.store.ready
        word = ingest.store.payload
        answered = table.answers.valid & table.answers.ready
        answer = table.answers.payload

        def slot_of(address):
            return sum((address >= amap.slot_range(s)[0]).as_unsigned() for s in range(1, SLOTS))

        # -- every burst inside one slot
        with m.If(port.executing):
            m.d.comb += [
                Assert(end <= amap.end, "a burst past the last slot"),
                Assert(slot_of(first) == slot_of(end - 1), "a burst across two slots"),
            ]

        # -- words go to the slot opened for their frame
        owner = Array(Signal(2, name=f"owner{s}") for s in range(SLOTS))
        owned = Array(Signal(name=f"owned{s}") for s in range(SLOTS))
        with m.If(opened.valid):
            m.d.sync += [owner[opened.payload.slot].eq(opened.payload.frame), owned[opened.payload.slot].eq(1)]
        with m.If(admitted):
            m.d.comb += [
                Assert(word.slot < SLOTS, "a word for a slot beyond the store"),
                Assert(owned[word.slot] & (owner[word.slot] == ingest.words.payload.frame),
                       "a word for a slot not opened for its frame"),
            ]

        # -- a slot given out is not written until it is opened again
        given = Array(Signal(name=f"given{s}") for s in range(SLOTS))
        with m.If(answered):
            m.d.sync += given[answer.slot].eq(1)
        with m.If(opened.valid):
            m.d.sync += given[opened.payload.slot].eq(0)
        with m.If(port.executing):
            m.d.comb += Assert(~given[slot_of(first)], "a write into a slot given to the sequencer")

        # -- a watched place: written only where admitted, and complete before it is given
        slot, plane, row = AnyConst(2), AnyConst(3), AnyConst(len(word.row))
        m.d.comb += Assume(slot < SLOTS)
        target = Signal(30)
        m.d.comb += target.eq(amap.address(slot, plane, row))
        covers = port.executing & (first <= target) & (target < end)
        admissions, writes = Signal(8), Signal(8)
        with m.If(admitted & (word.slot == slot) & (word.plane == plane) & (word.row == row)):
            m.d.sync += admissions.eq(admissions + 1)
        with m.If(covers):
            m.d.sync += writes.eq(writes + 1)
        m.d.comb += Assert(writes <= admissions, "a write where no word was admitted")

        # complete: the watched row has arrived whole since the slot was opened, and every word
        # admitted for the watched place is in memory (the writer keeps their order)
        arrived = Signal()
        with m.If(admitted & (word.slot == slot) & (word.row == row) & word.last):
            m.d.sync += arrived.eq(1)
        with m.If(opened.valid & (opened.payload.slot == slot)):
            m.d.sync += arrived.eq(0)
        with m.If(answered & (answer.slot == slot)):
            m.d.comb += [
                Assert(arrived, "a frame given before all its rows arrived"),
                Assert(writes == admissions, "a frame given before its words are in memory"),
            ]
        # the subjects: write bursts, and a frame given out whose watched place was written
        # (a second frame given out from one slot, and a slot opened again and written after
        # it was given out, lie beyond the depth the store's check affords)
        m.d.comb += [
            Cover(port.executing, "a write burst"),
            Cover(answered & (answer.slot == slot) & (writes != 0), "a frame given out, its watched place written"),
        ]

    return prop


def _top(mode):
    from gateware.store.store import Store
    with _short_blocks():
        store = Store(DMD, slots=SLOTS, frame_bits=2, fifo_depth=64, read_width=64)
        top = FormalTop(DomainRenamer({"dmd": "sync"})(store), [stream_rules(), _properties(store, mode)],
                        driven=("mcb_write",))
        return Fragment.get(top, None)


def store_checks():
    return [Check(f"store writes and frames given ({mode})", "Store", lambda mode=mode: _top(mode),
                  depth=depth, quick=quick)
            for mode, depth, quick in (("streaming", 48, None), ("sequence", 48, None))]
