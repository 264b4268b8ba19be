"""First-in first-out queues of any payload shape, with typed stream ports.

:class:`amaranth.lib.fifo.SyncFIFOBuffered` and :class:`~amaranth.lib.fifo.AsyncFIFO` carry
plain bit vectors; these wrap them so that both ends are streams of the payload's own shape (a
:class:`~amaranth.lib.data.Struct`, say) and join with :func:`amaranth.lib.wiring.connect`.
"""

from amaranth import Module, Shape
from amaranth.lib import fifo, stream, wiring
from amaranth.lib.wiring import In, Out

__all__ = ["Queue", "AsyncQueue"]


def _join(m, inner, outer):
    """Wire a FIFO's plain streams to the typed ones of ``outer``."""
    m.d.comb += [
        inner.w_stream.valid.eq(outer.w_stream.valid),
        inner.w_stream.payload.eq(outer.w_stream.payload),
        outer.w_stream.ready.eq(inner.w_stream.ready),
        outer.r_stream.valid.eq(inner.r_stream.valid),
        outer.r_stream.payload.eq(inner.r_stream.payload),
        inner.r_stream.ready.eq(outer.r_stream.ready),
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
        _join(m, inner, self)
        m.d.comb += self.level.eq(inner.level)
        return m


class AsyncQueue(wiring.Component):
    """A queue between two clock domains (:class:`~amaranth.lib.fifo.AsyncFIFO`).

    Parameters
    ----------
    shape : shape-castable
    depth : int
    w_domain, r_domain : str

    Members
    -------
    w_stream : In(stream.Signature(shape))
        In ``w_domain``.
    r_stream : Out(stream.Signature(shape))
        In ``r_domain``.
    """

    def __init__(self, shape, depth, *, w_domain, r_domain):
        self._width, self._depth = Shape.cast(shape).width, depth
        self._domains = dict(w_domain=w_domain, r_domain=r_domain)
        super().__init__({
            "w_stream": In(stream.Signature(shape)),
            "r_stream": Out(stream.Signature(shape)),
        })

    def elaborate(self, platform):
        m = Module()
        m.submodules.fifo = inner = fifo.AsyncFIFO(width=self._width, depth=self._depth, **self._domains)
        _join(m, inner, self)
        return m
