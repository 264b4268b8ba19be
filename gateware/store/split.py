"""Transfers of several words as one word a transfer."""

from amaranth import Module, Signal
from amaranth.lib import stream, wiring
from amaranth.lib.wiring import In, Out

__all__ = ["Split"]


class Split(wiring.Component):
    """Each transfer of ``words`` words of ``width`` bits becomes ``words`` transfers of one, the
    word in the low bits first. No buffering: ``words`` out is ``words`` in, word by word.

    Members
    -------
    wide : In(stream.Signature(width * words))
    narrow : Out(stream.Signature(width))
    """

    def __init__(self, width, words):
        self._width, self._words = width, words
        super().__init__({
            "wide": In(stream.Signature(width * words)),
            "narrow": Out(stream.Signature(width)),
        })

    def elaborate(self, platform):
        m = Module()
        index = Signal(range(self._words))
        last = index == self._words - 1
        m.d.comb += [
            self.narrow.valid.eq(self.wide.valid),
            self.narrow.payload.eq(self.wide.payload.word_select(index, self._width)),
            self.wide.ready.eq(self.narrow.ready & last),
        ]
        with m.If(self.narrow.valid & self.narrow.ready):
            m.d.sync += index.eq(index + 1)
            with m.If(last):
                m.d.sync += index.eq(0)
        return m
