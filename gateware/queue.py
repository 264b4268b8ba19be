"""First-in first-out queues of any payload shape, with typed stream ports.

:class:`amaranth.lib.fifo.SyncFIFOBuffered` and :class:`~amaranth.lib.fifo.AsyncFIFO` carry
plain bit vectors; these wrap them so that both ends are streams of the payload's own shape (a
:class:`~amaranth.lib.data.Struct`, say) and join with :func:`amaranth.lib.wiring.connect`.
"""

from amaranth import DomainRenamer, Module, Shape
from amaranth.lib import fifo, stream, wiring
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


class Queue(wiring.Component):
    """A synchronous queue (:class:`~amaranth.lib.fifo.SyncFIFOBuffered`).

    Parameters
    ----------
    shape : shape-castable
        The payload.
    depth : int

    Members
    -------
    w_stream : In(stream.Signature(shape))
    r_stream : Out(stream.Signature(shape))
    level : Out(range(depth + 1))
        Payloads queued.
    """

    def __init__(self, shape, depth):
        self._width, self._depth = Shape.cast(shape).width, depth
        super().__init__({
            "w_stream": In(stream.Signature(shape)),
            "r_stream": Out(stream.Signature(shape)),
            "level": Out(range(depth + 1)),
        })

    def elaborate(self, platform):
        m = Module()
        m.submodules.fifo = inner = fifo.SyncFIFOBuffered(width=self._width, depth=self._depth)
        _join(m, inner, self.w_stream, self.r_stream)
        m.d.comb += self.level.eq(inner.level)
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
