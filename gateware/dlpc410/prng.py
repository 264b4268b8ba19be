"""On-chip Bernoulli pattern source: pseudo-random 1-bit rows that need no memory bandwidth.

xorshift64 (shifts 13, 7, 17), one 64-bit word per step: every bit is a fair coin, so each
pattern is a row of a Bernoulli(1/2) measurement matrix for compressed sensing. The host
rebuilds the same patterns with :mod:`spec.prng`. A four-bus DMD takes two
consecutive words per cycle (the same sequence, two steps at a time).
"""

from amaranth import Cat, Module, Mux, Signal
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from spec.prng import ZERO_SEED

__all__ = ["Prng"]


def _step(state):
    a = state ^ (state << 13)[:64]
    b = a ^ (a >> 7)
    return b ^ (b << 17)[:64]


class Prng(wiring.Component):
    """xorshift64 word source.

    Parameters
    ----------
    words : int
        Words per cycle (1, or 2 for a four-bus beat): ``word`` holds that many consecutive
        words of the sequence, the first in the low bits.

    Members
    -------
    seed : In(64)
        Loaded when ``reseed`` is high (zero is replaced by :data:`prng.ZERO_SEED`).
    reseed : In(1)
    next : In(1)
        Take ``word`` this cycle; the next word follows on the next cycle.
    word : Out(64 * words)
        The current words (the state after one step from the seed, then ``words`` steps per
        ``next``).
    """

    def __init__(self, words=1):
        self._words = words
        super().__init__({"seed": In(64), "reseed": In(1), "next": In(1), "word": Out(64 * words)})

    def elaborate(self, platform):
        m = Module()
        state = Signal(64, init=_const_step(ZERO_SEED))
        seeded = Mux(self.seed == 0, ZERO_SEED, self.seed)
        with m.If(self.reseed):
            m.d.sync += state.eq(_step(seeded))
        seq = [state]
        for _ in range(self._words):
            seq.append(_step(seq[-1]))
        with m.Elif(self.next):
            m.d.sync += state.eq(seq[-1])
        m.d.comb += self.word.eq(Cat(*seq[:-1]))
        return m


def _const_step(value):
    from spec.prng import step
    return step(value)
