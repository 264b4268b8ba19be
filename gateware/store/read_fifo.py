"""The plane reader's word FIFO: block RAM, and a read side that starts only from registers."""

from amaranth import Module, Signal
from amaranth.lib import stream, wiring
from amaranth.lib.memory import Memory
from amaranth.lib.wiring import In, Out
from amaranth.utils import exact_log2

__all__ = ["ReadFifo"]

#: Words the output queue holds: with the word read from the memory last cycle, enough to read
#: one word a cycle while deciding each read from registers alone.
_OUTPUT_WORDS = 3


class ReadFifo(wiring.Component):
    """A FIFO of ``depth`` words in block RAM for a writer that keeps count of its room.

    The write side has no ``ready``: the writer never writes more words than the FIFO holds (the
    plane reader reserves room for each burst before asking the memory for it). The read side
    passes a word a cycle, and none of its logic goes through ``ready`` into the memory's pointers:
    the memory is read ahead into a three-word output queue by registered state alone, and
    ``r_stream.ready`` only moves words within that queue. A word written is offered three
    cycles later at the earliest.

    Parameters
    ----------
    width : int
    depth : int
        Words in the memory, a power of two.

    Members
    -------
    w_stream : In(stream.Signature(width, always_ready=True))
        Words in.
    r_stream : Out(stream.Signature(width))
        The words in the order written.
    """

    def __init__(self, width, depth):
        self._width, self._depth = width, depth
        self._bits = exact_log2(depth)
        super().__init__({
            "w_stream": In(stream.Signature(width, always_ready=True)),
            "r_stream": Out(stream.Signature(width)),
        })

    def elaborate(self, platform):
        m = Module()
        bits = self._bits
        m.submodules.storage = storage = Memory(shape=self._width, depth=self._depth, init=[])
        w_port, r_port = storage.write_port(), storage.read_port(transparent_for=())
        # one bit more than the address: equal pointers mean empty, not full
        produce, consume = Signal(bits + 1), Signal(bits + 1)
        m.d.comb += [w_port.addr.eq(produce[:bits]), w_port.data.eq(self.w_stream.payload),
                     w_port.en.eq(self.w_stream.valid)]
        with m.If(self.w_stream.valid):
            m.d.sync += produce.eq(produce + 1)

        # the output queue: entry 0 is offered; held[i]: entry i holds a word (a thermometer code)
        entries = [Signal(self._width, name=f"entry{i}") for i in range(_OUTPUT_WORDS)]
        held = Signal(_OUTPUT_WORDS)
        fetched = Signal()                     # the memory's output is the word read last cycle
        # read when the queue has room for this word after the one fetched: at most two words
        # in the queue and the memory's output together, whatever is taken this cycle
        fetch = (produce != consume) & ~held[-1] & ~(held[-2] & fetched)
        m.d.comb += [r_port.addr.eq(consume[:bits]), r_port.en.eq(fetch)]
        with m.If(fetch):
            m.d.sync += consume.eq(consume + 1)
        m.d.sync += fetched.eq(fetch)

        take = self.r_stream.valid & self.r_stream.ready
        m.d.comb += [self.r_stream.valid.eq(held[0]), self.r_stream.payload.eq(entries[0])]
        for i, entry in enumerate(entries):
            # a word taken moves the others down; the word fetched goes to the first free entry
            # (the free entries above it load it too, unmarked)
            with m.If(take | ~held[i]):
                m.d.sync += entry.eq(r_port.data)
            if i + 1 < len(entries):
                with m.If(take & held[i + 1]):
                    m.d.sync += entry.eq(entries[i + 1])
        with m.If(fetched & ~take):
            m.d.sync += held.eq((held << 1) | 1)
        with m.Elif(take & ~fetched):
            m.d.sync += held.eq(held >> 1)
        return m
