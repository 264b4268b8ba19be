"""Between the store and the sequencer: one frame on offer, with its occupancy map at hand.

The store hands out a frame per ``ask`` and answers occupancy one block at a time; the sequencer
wants a frame offered whenever one is due and the occupancy of a whole slot at once. The broker
keeps one ask outstanding, copies the answered slot's occupancy into a small cache (one byte per
block), and only then offers the frame, so that the sequencer never sees a frame whose map is not
yet known.

While the store has lost its memory (``store_lost``) every slot's map reads empty, so that the
frames the sequencer holds from before play dark and nothing is read for them.
"""

from amaranth import Array, Module, Signal
from amaranth.lib import data, stream, wiring
from amaranth.lib.wiring import In, Out

from gateware.store.layouts import SLOT_BITS, FrameInfo, OccupancySignature

__all__ = ["FrameBroker"]


class FrameBroker(wiring.Component):
    """Frame hand-over from :class:`gateware.store.Store` to :class:`gateware.dlpc410.sequencer.Sequencer`.

    Parameters
    ----------
    dmd : DmdType
    slots : int
        Frame slots of the store.

    Members
    -------
    ask : Out(stream.Signature(0))
        Asks the store for a frame (``dmd``).
    offered : In(stream.Signature(FrameInfo))
        The store's answer.
    store_occupancy : Out(OccupancySignature())
        The store's occupancy read port.
    frames : Out(stream.Signature(FrameInfo))
        The frame on offer to the sequencer; its occupancy is in the cache.
    occ_slot : In(SLOT_BITS)
        The sequencer's occupancy lookup ...
    occupancy : Out(ArrayLayout(8, blocks))
        ... answered one cycle later for every block.
    store_lost : In(1)
        The store lost its memory: forget every map.
    """

    def __init__(self, dmd, *, slots=4):
        self._dmd, self._slots = dmd, slots
        super().__init__({
            "ask": Out(stream.Signature(0)),
            "offered": In(stream.Signature(FrameInfo)),
            "store_occupancy": Out(OccupancySignature()),
            "frames": Out(stream.Signature(FrameInfo)),
            "occ_slot": In(SLOT_BITS),
            "occupancy": Out(data.ArrayLayout(8, dmd.blocks)),
            "store_lost": In(1),
        })

    def elaborate(self, platform):
        m = Module()
        blocks = self._dmd.blocks
        cache = Array(Array(Signal(8, name=f"occ_s{s}_b{b}") for b in range(blocks))
                      for s in range(self._slots))
        info = Signal(FrameInfo)
        block = Signal(range(blocks + 1))      # the block asked for
        # the block whose planes come back this cycle (one-hot, registered: each cache byte's
        # write enable is a small AND of flip-flops)
        answered = Signal(blocks)
        answering = Signal()

        m.d.sync += [answering.eq(0), answered.eq(0)]
        with m.FSM():
            with m.State("ASK"):
                m.d.comb += self.ask.valid.eq(1)
                with m.If(self.ask.ready):
                    m.next = "WAIT"
            with m.State("WAIT"):
                m.d.comb += self.offered.ready.eq(1)
                with m.If(self.offered.valid):
                    m.d.sync += [info.eq(self.offered.payload), block.eq(0)]
                    m.next = "SCAN"
            with m.State("SCAN"):
                # Block b is asked for on one cycle and its planes written on the next.
                m.d.comb += [self.store_occupancy.slot.eq(info.slot), self.store_occupancy.block.eq(block)]
                m.d.sync += block.eq(block + 1)
                with m.If(block == blocks):
                    m.next = "OFFER"
                with m.Else():
                    m.d.sync += [answering.eq(1), answered.eq(1 << block)]
            with m.State("OFFER"):
                m.d.comb += [self.frames.valid.eq(1), self.frames.payload.eq(info)]
                with m.If(self.frames.ready):
                    m.next = "ASK"

        for s in range(self._slots):
            for b in range(blocks):
                with m.If(answering & (info.slot == s) & answered[b]):
                    m.d.sync += cache[s][b].eq(self.store_occupancy.planes)
        with m.If(self.store_lost):
            # written last, so this wins over a scan under way
            m.d.sync += [cache[s][b].eq(0) for s in range(self._slots) for b in range(blocks)]
        for b in range(blocks):
            m.d.sync += self.occupancy[b].eq(cache[self.occ_slot][b])
        return m
