"""The sequencer's side of the frame slots: asks and releases into ``sync``, answers into ``dmd``.

Asks and releases cross in FIFOs of their own, so that a release never waits behind an ask the
slot table cannot answer yet: in a stored sequence of one or two frames, the next frame to play
is the slot the sequencer is about to hand back. Both FIFOs are built alike and clocked alike,
so a release written before an ask is readable no later than the ask, and the slot table takes
a release first.

On the ``dmd`` side each FIFO sits behind a one-entry register stage
(:class:`~gateware.queue.AsyncQueue`'s ``staged``), so that its pointer logic in that domain
starts only from registers: the sequencer's and the broker's logic on these streams and the
FIFO's own do not add up on one path. A stage passes an ask, a release or an answer every other
cycle, and adds a cycle to its crossing.
"""

from amaranth import Module
from amaranth.lib import stream, wiring
from amaranth.lib.wiring import In, Out

from ..queue import AsyncQueue
from .layouts import SLOT_BITS, FrameInfo

__all__ = ["SlotCrossing"]


class SlotCrossing(wiring.Component):
    """Clock-domain crossing of the sequencer's asks, releases and answers.

    Parameters
    ----------
    depth : int
        Entries each FIFO holds.

    Members
    -------
    ask : In(stream.Signature(0))
        Each transfer asks for one frame (``dmd``).
    release : In(stream.Signature(SLOT_BITS))
        Slots the sequencer hands back (``dmd``).
    frames : Out(stream.Signature(FrameInfo))
        The answers (``dmd``).
    asks : Out(stream.Signature(0))
        The asks, in order (``sync``).
    releases : Out(stream.Signature(SLOT_BITS))
        The releases, in order (``sync``).
    answers : In(stream.Signature(FrameInfo))
        Answers to the asks (``sync``).
    """

    def __init__(self, *, depth=4):
        self._depth = depth
        super().__init__({
            "ask": In(stream.Signature(0)),
            "release": In(stream.Signature(SLOT_BITS)),
            "frames": Out(stream.Signature(FrameInfo)),
            "asks": Out(stream.Signature(0)),
            "releases": Out(stream.Signature(SLOT_BITS)),
            "answers": In(stream.Signature(FrameInfo)),
        })

    def elaborate(self, platform):
        m = Module()
        crossings = [("releases", self.release, self.releases, SLOT_BITS, "dmd", "sync"),
                     ("answers", self.answers, self.frames, FrameInfo, "sync", "dmd")]
        for name, source, sink, shape, w_domain, r_domain in crossings:
            m.submodules[name] = fifo = self._crossing(shape, w_domain, r_domain)
            wiring.connect(m, wiring.flipped(source), fifo.w_stream)
            wiring.connect(m, fifo.r_stream, wiring.flipped(sink))
        # An ask carries no payload, but a memory of zero bits does not synthesise: one bit, unused.
        m.submodules.asks = asks = self._crossing(1, "dmd", "sync")
        m.d.comb += [asks.w_stream.valid.eq(self.ask.valid), self.ask.ready.eq(asks.w_stream.ready),
                     self.asks.valid.eq(asks.r_stream.valid), asks.r_stream.ready.eq(self.asks.ready)]
        return m

    def _crossing(self, shape, w_domain, r_domain):
        return AsyncQueue(shape, self._depth, w_domain=w_domain, r_domain=r_domain, staged=("dmd",))
