"""First-in first-out queues of any payload shape, with typed stream ports.

:class:`Queue` passes payloads in the cycles of :class:`amaranth.lib.fifo.SyncFIFOBuffered` (the
same ``ready``, ``valid`` and payload on every cycle), built so that no carry chain follows a
stream's ``ready`` or ``valid``: its fill is a thermometer code, not a binary count updated by an
adder after the enables. :class:`AsyncQueue` wraps
:class:`~amaranth.lib.fifo.AsyncFIFO`. Both ends of each are streams of the payload's own shape (a
:class:`~amaranth.lib.data.Struct`, say) and join with :func:`amaranth.lib.wiring.connect`.
"""

from amaranth import Cat, DomainRenamer, Module, Mux, Shape, Signal
from amaranth.lib import fifo, stream, wiring
from amaranth.lib.memory import Memory
from amaranth.lib.wiring import In, Out

__all__ = ["Queue", "AsyncQueue"]


def _join(m, inner, w_stream, r_stream):
    """Wire a FIFO's plain streams to typed ones: ``w_stream`` writes it, ``r_stream`` reads it."""
    m.d.comb += [
        inner.w_stream.valid.eq(w_stream.valid),
        inner.w_stream.payload.eq(w_stream.payload),
        w_stream.ready.eq(inner.w_stream.ready),
        r_stream.valid.eq(inner.r_stream.valid),
        r_stream.payload.eq(inner.r_stream.payload),
        inner.r_stream.ready.eq(r_stream.ready),
    ]


def _next(pointer, modulo):
    """``pointer + 1``, wrapping at ``modulo``."""
    if modulo == 1 << len(pointer):
        return (pointer + 1)[:len(pointer)]
    return Mux(pointer == modulo - 1, 0, pointer + 1)


class Queue(wiring.Component):
    """A synchronous queue of ``depth`` payloads.

    A memory of ``depth - 1`` payloads and an output register, as
    :class:`~amaranth.lib.fifo.SyncFIFOBuffered` has them, and in its cycles: a payload written
    into an empty queue is offered two cycles later (one, at depth 1), and ``w_stream.ready`` is
    low only while the memory is full. (At depth 1 the register alone: it takes a payload every
    other cycle.)

    Parameters
    ----------
    shape : shape-castable
        The payload.
    depth : int

    Members
    -------
    w_stream : In(stream.Signature(shape))
    r_stream : Out(stream.Signature(shape))
    fill : Out(depth)
        A thermometer code of the payloads queued: bit ``i`` is high while more than ``i`` are.
        Each bit is one LUT from registers.
    """

    def __init__(self, shape, depth):
        assert depth >= 1
        self._width, self._depth = Shape.cast(shape).width, depth
        super().__init__({
            "w_stream": In(stream.Signature(shape)),
            "r_stream": Out(stream.Signature(shape)),
            "fill": Out(depth),
        })

    def elaborate(self, platform):
        m = Module()
        w, r = self.w_stream, self.r_stream
        valid = Signal()                       # the output register holds a payload
        m.d.comb += r.valid.eq(valid)
        if self._depth == 1:
            m.d.comb += [w.ready.eq(~valid), self.fill.eq(valid)]
            with m.If(w.valid & ~valid):
                m.d.sync += [r.payload.eq(w.payload), valid.eq(1)]
            with m.If(r.ready & valid):
                m.d.sync += valid.eq(0)
            return m

        inner = self._depth - 1
        m.submodules.storage = storage = Memory(shape=self._width, depth=inner, init=[])
        w_port, r_port = storage.write_port(), storage.read_port(transparent_for=())
        # held[i]: more than i payloads in the memory (a thermometer code, so that each bit's
        # next value is one LUT of the enables and its neighbours, with no carry chain)
        held = Signal(inner)
        produce, consume = Signal(range(inner)), Signal(range(inner))
        put = w.valid & ~held[-1]
        fetch = held[0] & (~valid | r.ready)   # the memory's next payload to the output register
        m.d.comb += [
            w.ready.eq(~held[-1]),
            w_port.addr.eq(produce), w_port.data.eq(w.payload), w_port.en.eq(put),
            r_port.addr.eq(consume), r_port.en.eq(fetch), r.payload.eq(r_port.data),
        ]
        with m.If(put):
            m.d.sync += produce.eq(_next(produce, inner))
        with m.If(fetch):
            m.d.sync += consume.eq(_next(consume, inner))
        with m.If(put & ~fetch):
            m.d.sync += held.eq(Cat(1, held[:-1]))
        with m.Elif(fetch & ~put):
            m.d.sync += held.eq(held[1:])
        with m.If(fetch):
            m.d.sync += valid.eq(1)
        with m.Elif(r.ready):
            m.d.sync += valid.eq(0)
        # more than i queued: more than i in the memory, or i there and one in the register
        m.d.comb += self.fill.eq(Cat(*(held[i] | (valid & (held[i - 1] if i else 1)) for i in range(inner)),
                                     valid & held[-1]))
        return m


class AsyncQueue(wiring.Component):
    """A queue between two clock domains (:class:`~amaranth.lib.fifo.AsyncFIFO`).

    Parameters
    ----------
    shape : shape-castable
    depth : int
    w_domain, r_domain : str
    staged : tuple of str
        The domains among ``w_domain`` and ``r_domain`` whose end of the FIFO sits behind a
        one-entry register stage (a :class:`Queue` of depth 1, which passes a payload every other
        cycle): the FIFO's pointer logic there then starts only from registers, so that it stays
        within a few LUT levels whatever logic drives or takes the stream (the FIFO's own read or
        write enable through its pointers is about four). Each stage adds a cycle of latency.

    Members
    -------
    w_stream : In(stream.Signature(shape))
        In ``w_domain``.
    r_stream : Out(stream.Signature(shape))
        In ``r_domain``.
    """

    def __init__(self, shape, depth, *, w_domain, r_domain, staged=()):
        assert set(staged) <= {w_domain, r_domain}
        self._shape, self._width, self._depth = shape, Shape.cast(shape).width, depth
        self._domains = dict(w_domain=w_domain, r_domain=r_domain)
        self._staged = staged
        super().__init__({
            "w_stream": In(stream.Signature(shape)),
            "r_stream": Out(stream.Signature(shape)),
        })

    def elaborate(self, platform):
        m = Module()
        m.submodules.fifo = inner = fifo.AsyncFIFO(width=self._width, depth=self._depth, **self._domains)
        # each end: the outer stream, or a one-entry stage between it and the FIFO
        ends = {}
        for end, domain in (("w", self._domains["w_domain"]), ("r", self._domains["r_domain"])):
            ends[end] = getattr(self, f"{end}_stream")
            if domain in self._staged:
                m.submodules[f"{end}_stage"] = stage = DomainRenamer(domain)(Queue(self._shape, 1))
                if end == "w":
                    wiring.connect(m, wiring.flipped(self.w_stream), stage.w_stream)
                    ends["w"] = stage.r_stream
                else:
                    wiring.connect(m, stage.r_stream, wiring.flipped(self.r_stream))
                    ends["r"] = stage.w_stream
        _join(m, inner, ends["w"], ends["r"])
        return m
