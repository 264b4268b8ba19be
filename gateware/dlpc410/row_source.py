"""Row data for the bus: the store's words as beats, or the on-chip pattern source.

The store's 64-bit words go into a FIFO of ``WORD_FIFO_ROWS`` rows of beats (a four-bus DMD takes
two words per beat: the first on DIN_A/B, the second on C/D, so words are paired first). The bus
starts a row only when a whole row is buffered. With the pattern source
(:attr:`~spec.registers.Source.PRNG`) beats come from :class:`~gateware.dlpc410.prng.Prng` and
need no memory bandwidth.

The row source also counts the words asked of the store and not yet taken (in rows, and the
beats of the row being taken): when the frame control flushes stale loads, those still owed are
discarded as they arrive.
"""

from amaranth import Array, Cat, Module, Mux, Signal
from amaranth.lib import stream, wiring
from amaranth.lib.wiring import In, Out
from amaranth.utils import ceil_log2

from spec.schedule import WORD_FIFO_ROWS, row_cycles

from ..queue import Queue
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
    row_started : In(1)
        The bus reads the first beat of a row this cycle.
    beats : Out(stream.Signature(bits_per_dclk * beats))
        One cycle's beats of a row; the bus takes one a cycle through a row.
    row_ready : Out(1)
        A whole row is there for the bus's next decision (always, from the pattern source):
        registered, so counted with the words that arrived and without the rows begun on the
        cycle before.
    drained : Out(1)
        No word asked of the store is still to be taken (registered: as of the cycle before).
    seed, reseed : In(64), In(1)
        Seed of the pattern source.
    """

    def __init__(self, dmd, *, beats=1, store_words=1):
        width = dmd.bits_per_dclk * beats
        assert width % (64 * store_words) == 0
        self._dmd, self._beats, self._store_words = dmd, beats, store_words
        super().__init__({
            "regs": In(Registers),
            "words": In(stream.Signature(64 * store_words)),
            "asked": In(1),
            "flushing": In(1),
            "row_started": In(1),
            "beats": Out(stream.Signature(width)),
            "row_ready": Out(1),
            "drained": Out(1),
            "seed": In(64),
            "reseed": In(1),
        })

    def elaborate(self, platform):
        m = Module()
        dmd = self._dmd
        cycles_per_row = row_cycles(dmd, self._beats)
        width = dmd.bits_per_dclk * self._beats
        wpc = width // 64                      # words per cycle
        use_prng = self.regs.source == Source.PRNG

        m.submodules.prng = prng = Prng(words=wpc)
        m.submodules.fifo = buffer = Queue(width, depth=WORD_FIFO_ROWS * cycles_per_row)
        m.d.comb += [prng.seed.eq(self.seed), prng.reseed.eq(self.reseed)]
        transfers = wpc // self._store_words   # store transfers per cycle of the row
        if transfers == 1:
            wiring.connect(m, wiring.flipped(self.words), buffer.w_stream)
        else:
            # the first transfers of a cycle wait for its last one (a cycle's words in order)
            held = Array(Signal(64 * self._store_words, name=f"held{i}") for i in range(transfers - 1))
            count = Signal(range(transfers))
            last = count == transfers - 1
            m.d.comb += [buffer.w_stream.payload.eq(Cat(*held, self.words.payload)),
                         buffer.w_stream.valid.eq(self.words.valid & last),
                         self.words.ready.eq(~last | buffer.w_stream.ready)]
            with m.If(self.words.valid & self.words.ready):
                m.d.sync += count.eq(Mux(last, 0, count + 1))
                with m.If(~last):
                    m.d.sync += held[count].eq(self.words.payload)

        out = buffer.r_stream
        # owed: rows asked of the store, less the rows taken (``cycles_per_row`` beats take a row), counted
        # apart (a request's rows, a row) and compared
        # (both wrap; at most ``rows`` are owed at a time)
        rows = (dmd.blocks + 2) * dmd.rows_per_block
        asked, taken_rows = Signal(ceil_log2(rows) + 1), Signal(ceil_log2(rows) + 1)
        beat = Signal(range(cycles_per_row))
        taken = out.ready & out.valid & ~use_prng
        discard = self.flushing & ~self.beats.ready & ~self.drained
        m.d.comb += [
            self.beats.valid.eq(use_prng | out.valid),
            self.beats.payload.eq(Mux(use_prng, prng.word, out.payload)),
            out.ready.eq(self.beats.ready & ~use_prng | discard),
            prng.next.eq(self.beats.ready & use_prng),
        ]
        # a whole row for the next decision (made next cycle on what is registered now, its first
        # beat read the cycle after): the beats arrived and not yet given to a row the bus began
        # (``free``; every row decided before has begun, as decisions are two cycles apart at
        # least). A beat arriving now is readable by then. The flag is chosen among four
        # comparisons of ``free`` with constants, so that no sum lies on its path.
        arriving = buffer.w_stream.valid & buffer.w_stream.ready
        free = Signal(range(WORD_FIFO_ROWS * cycles_per_row + 1))
        with m.If(self.flushing | use_prng):
            m.d.sync += free.eq(0)             # (the words owed are discarded as they arrive)
        with m.Else():
            m.d.sync += free.eq(free + arriving - Mux(self.row_started, cycles_per_row, 0))
        enough = Mux(self.row_started, Mux(arriving, free >= 2 * cycles_per_row - 1, free >= 2 * cycles_per_row),
                     Mux(arriving, free >= cycles_per_row - 1, free >= cycles_per_row))
        m.d.sync += [self.row_ready.eq(use_prng | (enough & ~self.flushing)),
                     self.drained.eq((asked == taken_rows) & (beat == 0))]
        with m.If(self.asked):
            m.d.sync += asked.eq(asked + dmd.rows_per_block)
        with m.If(taken):
            m.d.sync += beat.eq(Mux(beat == cycles_per_row - 1, 0, beat + 1))
            with m.If(beat == cycles_per_row - 1):
                m.d.sync += taken_rows.eq(taken_rows + 1)
        return m
