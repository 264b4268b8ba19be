"""On-chip Bernoulli pattern source: pseudo-random 1-bit rows that need no memory bandwidth.

xorshift64 (shifts 13, 7, 17), one 64-bit word per step: every bit is a fair coin, so each
pattern is a row of a Bernoulli(1/2) measurement matrix for compressed sensing. The host
rebuilds the same patterns with :mod:`spec.prng`. A four-bus DMD takes two
consecutive words per cycle (the same sequence, two steps at a time).
"""

from amaranth import Cat, Const, Module, Mux, Signal
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from spec.prng import ZERO_SEED

__all__ = ["Prng"]


def _matrix(steps):
    """xorshift64's ``steps`` steps as a map over GF(2): per output bit, the input bits whose XOR
    it is (the step is linear)."""
    from spec.prng import step
    columns = []
    for i in range(64):
        value = 1 << i
        for _ in range(steps):
            value = step(value)
        columns.append(value)
    return [[i for i in range(64) if columns[i] >> bit & 1] for bit in range(64)]


def _steps(state, steps):
    """``steps`` xorshift64 steps of ``state``, each output bit one balanced XOR of the input bits
    it depends on (few LUT levels, where the steps in a row would chain)."""
    return Cat(_xor([state[i] for i in taps]) for taps in _matrix(steps))


def _xor(bits):
    while len(bits) > 1:
        bits = [bits[i] ^ bits[i + 1] if i + 1 < len(bits) else bits[i] for i in range(0, len(bits), 2)]
    return bits[0] if bits else Const(0, 1)


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
        Loaded when ``reseed`` is high (zero is replaced by :data:`prng.ZERO_SEED`), on the
        cycle after.
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
        # the seed, checked for zero, a cycle before its first step
        seeded, reseeding = Signal(64), Signal()
        m.d.sync += [seeded.eq(Mux(self.seed == 0, ZERO_SEED, self.seed)), reseeding.eq(self.reseed)]
        with m.If(reseeding):
            m.d.sync += state.eq(_steps(seeded, 1))
        with m.Elif(self.next):
            m.d.sync += state.eq(_steps(state, self._words))
        m.d.comb += self.word.eq(Cat(*(_steps(state, k) if k else state for k in range(self._words))))
        return m


def _const_step(value):
    from spec.prng import step
    return step(value)
