"""Row data for the bus: the store's words as beats, or the on-chip pattern source.

The store's 64-bit words go into a FIFO of ``WORD_FIFO_ROWS`` rows of beats (a four-bus DMD takes
two words per beat: the first on DIN_A/B, the second on C/D, so words are paired first). The bus
starts a row only when a whole row is buffered. With the pattern source
(:attr:`~spec.registers.Source.PRNG`) beats come from :class:`~gateware.dlpc410.prng.Prng` and
need no memory bandwidth.

The row source also counts the words asked of the store and not yet taken: when the frame
control flushes stale loads, those still owed are discarded as they arrive.
"""

from amaranth import Cat, Module, Mux, Signal
from amaranth.lib import fifo, stream, wiring
from amaranth.lib.wiring import In, Out

from spec.schedule import WORD_FIFO_ROWS

from ..registers import Registers, Source
from .prng import Prng

__all__ = ["RowSource"]


class RowSource(wiring.Component):
    """Beats for the bus.

    Parameters
    ----------
    dmd : :class:`spec.facts.DmdType`

    Members
    -------
    regs : In(Registers)
        ``source`` chooses the store or the pattern source.
    words : In(stream.Signature(64))
        The store's words, in the order requested.
    asked : In(1)
        A request for ``rows_per_block`` rows was taken by the store this cycle.
    flushing : In(1)
        Discard the words still owed (while the bus reads none).
    beats : Out(stream.Signature(bits_per_dclk))
        One beat per DCLK cycle of a row; the bus takes one a cycle through a row.
    row_ready : Out(1)
        A whole row of beats is there (always, from the pattern source).
    owed : Out(range(...))
        Words asked of the store and not yet taken.
    seed, reseed : In(64), In(1)
        Seed of the pattern source.
    """

    def __init__(self, dmd):
        self._dmd = dmd
        super().__init__({
            "regs": In(Registers),
            "words": In(stream.Signature(64)),
            "asked": In(1),
            "flushing": In(1),
            "beats": Out(stream.Signature(dmd.bits_per_dclk)),
            "row_ready": Out(1),
            "owed": Out(range((dmd.blocks + 2) * dmd.words_per_plane + 1)),
            "seed": In(64),
            "reseed": In(1),
        })

    def elaborate(self, platform):
        m = Module()
        dmd = self._dmd
        R = dmd.dclk_per_row
        wpb = dmd.bits_per_dclk // 64         # words per beat
        use_prng = self.regs.source == Source.PRNG

        m.submodules.prng = prng = Prng(words=wpb)
        m.submodules.fifo = buffer = fifo.SyncFIFOBuffered(width=dmd.bits_per_dclk, depth=WORD_FIFO_ROWS * R)
        m.d.comb += [prng.seed.eq(self.seed), prng.reseed.eq(self.reseed)]
        if wpb == 1:
            wiring.connect(m, wiring.flipped(self.words), buffer.w_stream)
        else:
            # four buses: the first word of a beat waits for the second (A/B, then C/D)
            first = Signal(64)
            have = Signal()
            m.d.comb += [buffer.w_stream.payload.eq(Cat(first, self.words.payload)),
                         buffer.w_stream.valid.eq(self.words.valid & have),
                         self.words.ready.eq(~have | buffer.w_stream.ready)]
            with m.If(self.words.valid & self.words.ready):
                m.d.sync += [first.eq(self.words.payload), have.eq(~have)]

        out = buffer.r_stream
        discard = self.flushing & ~self.beats.ready & (self.owed != 0)
        m.d.comb += [
            self.beats.valid.eq(use_prng | out.valid),
            self.beats.payload.eq(Mux(use_prng, prng.word, out.payload)),
            out.ready.eq(self.beats.ready & ~use_prng | discard),
            prng.next.eq(self.beats.ready & use_prng),
            self.row_ready.eq(use_prng | (buffer.level >= R)),
        ]
        asked = Mux(self.asked, dmd.rows_per_block * dmd.words_per_row, 0)
        m.d.sync += self.owed.eq(self.owed + asked - Mux(out.ready & out.valid, wpb, 0))
        return m
