"""Between the store and the sequencer: one frame on offer, with its occupancy map at hand.

The store hands out a frame per ``ask`` and answers occupancy one block at a time; the sequencer
wants a frame offered whenever one is due and the occupancy of a whole slot at once. The broker
keeps one ask outstanding, gathers the answered slot's occupancy (one byte per block) and writes
it as the slot's row of a memory (one row per slot: block RAM, whatever the number of slots), and
only then offers the frame, so that the sequencer never sees a frame whose map is not yet known.

While the store has lost its memory (``store_lost``) every slot's map reads empty, so that the
frames the sequencer holds from before play dark and nothing is read for them: the broker clears
every row, one a cycle, and reads as empty until the sweep is over.
"""

from amaranth import Cat, Module, Mux, Signal
from amaranth.lib import data, stream, wiring
from amaranth.lib.memory import Memory
from amaranth.lib.wiring import In, Out

from gateware.store.layouts import SLOT_BITS, FrameInfo, OccupancySignature

__all__ = ["FrameBroker"]


class FrameBroker(wiring.Component):
    """Frame hand-over from :class:`gateware.store.Store` to :class:`gateware.dlpc410.sequencer.Sequencer`.

    Parameters
    ----------
    dmd : DmdType
    slots : int
        Frame slots of the store (at most ``2**SLOT_BITS``).

    Members
    -------
    ask : Out(stream.Signature(0))
        Asks the store for a frame (``dmd``).
    offered : In(stream.Signature(FrameInfo))
        The store's answer.
    store_occupancy : Out(OccupancySignature())
        The store's occupancy read port.
    frames : Out(stream.Signature(FrameInfo))
        The frame on offer to the sequencer; its slot's row is written before it is offered.
    occ_slot : In(SLOT_BITS)
        The sequencer's occupancy lookup ...
    occupancy : Out(ArrayLayout(8, blocks))
        ... answered one cycle later for every block.
    store_lost : In(1)
        The store lost its memory: forget every map. Every lookup from the cycle after it rises
        reads empty, until a frame is offered again after the clearing sweep (a row a cycle, over
        by ``slots - 1`` cycles after ``store_lost`` falls): then its slot reads its new map.
    """

    def __init__(self, dmd, *, slots=4):
        assert 2 <= slots <= 2**SLOT_BITS
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
        blocks, slots = self._dmd.blocks, self._slots
        # one row per slot
        m.submodules.cache = cache = Memory(shape=data.ArrayLayout(8, blocks), depth=slots, init=[])
        write = cache.write_port()
        # Not transparent: a slot's row is written the cycle before its frame is offered, so a
        # lookup never needs the row being written (and the output needs no bypass mux).
        read = cache.read_port()

        info = Signal(FrameInfo)
        block = Signal(range(blocks + 1))      # the block asked for
        # The blocks' planes as they come back, shifted in from the top: once the last block has
        # come back the whole row is at hand.
        staged = Signal(8 * blocks)
        row = Cat(staged[8:], self.store_occupancy.planes)

        # The clearing sweep: row 0 is zeroed every cycle the store is lost, then the others one
        # a cycle (``clearing``: rows from ``sweep`` on still to zero).
        clearing = Signal()
        sweep = Signal(range(slots))
        with m.If(self.store_lost):
            m.d.sync += [clearing.eq(1), sweep.eq(1)]
        with m.Elif(clearing):
            m.d.sync += sweep.eq(sweep + 1)
            with m.If(sweep == slots - 1):
                m.d.sync += clearing.eq(0)
        zeroing = self.store_lost | clearing

        # the store's map is looked up from registers alone, in every state (only SCAN uses the
        # answers): no decode of the state in front of the store's block RAM address
        m.d.comb += [self.store_occupancy.slot.eq(info.slot), self.store_occupancy.block.eq(block)]
        row_done = Signal()
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
                # Block b is asked for on one cycle and its planes come back on the next.
                m.d.sync += [block.eq(block + 1), staged.eq(row)]
                with m.If(zeroing):
                    # starts over after the sweep: the row is never written where the sweep
                    # would then zero it, nor from planes answered before the loss
                    m.d.sync += block.eq(0)
                with m.Elif(block == blocks):
                    # the last block's planes are here: the row is written now, the frame
                    # offered from the next cycle on
                    m.d.comb += row_done.eq(1)
                    m.next = "OFFER"
            with m.State("OFFER"):
                m.d.comb += self.frames.valid.eq(1)
                with m.If(self.frames.ready):
                    m.next = "ASK"

        # (the payload is the frame's register in every state, no decode of the state after it)
        m.d.comb += [
            self.frames.payload.eq(info),
            write.en.eq(zeroing | row_done),
            write.addr.eq(Mux(zeroing, Mux(self.store_lost, 0, sweep), info.slot)),
            write.data.eq(Mux(zeroing, 0, row)),
        ]
        # While clearing, lookups read row 0, zeroed when the loss began: the zeros come through
        # the address (and a register, ``clearing``), so that ``occupancy`` is the memory's output
        # register with no logic after it. (A read port's enable cannot give zeros: a disabled
        # port holds its last output.)
        m.d.comb += [
            read.addr.eq(Mux(clearing, 0, self.occ_slot)),
            self.occupancy.eq(read.data),
        ]
        return m
