"""Host-side reproduction of the on-chip Bernoulli pattern source, bit for bit.

The generator is xorshift64 (Marsaglia 2003, shifts 13, 7, 17): one step per 64-bit row word the
sequencer loads, the word being the state after the step. Each bit is a fair coin (p = 1/2), so
a pattern is a row of a Bernoulli(1/2) measurement matrix. A zero seed (a fixed point of
xorshift) is replaced by :data:`ZERO_SEED`.
"""

import numpy as np

__all__ = ["ZERO_SEED", "step", "words", "shown_patterns"]

MASK = (1 << 64) - 1
#: The state a zero seed is replaced with.
ZERO_SEED = 0x9E3779B97F4A7C15


def step(state):
    """One xorshift64 step."""
    state ^= (state << 13) & MASK
    state ^= state >> 7
    state ^= (state << 17) & MASK
    return state


def words(seed, count):
    """The first ``count`` words the source gives after being seeded with ``seed``."""
    state = seed & MASK or ZERO_SEED
    out = []
    for _ in range(count):
        state = step(state)
        out.append(state)
    return out


def shown_patterns(dmd, commands, seed):
    """Replay a command list (:func:`spec.schedule.simulate`'s ``commands``) with
    the source's words: the (rows, columns) 0/1 pattern each clocking pulse shows, in order."""
    n_rows = sum(1 for _t, kind, _a in commands if kind == "row")
    stream = iter(words(seed, n_rows * dmd.words_per_row))
    memory = np.zeros((dmd.rows, dmd.columns), dtype=np.uint8)
    mirrors = memory.copy()
    shown = []
    for _t, kind, arg in commands:
        if kind == "row":
            row = np.array([next(stream) for _ in range(dmd.words_per_row)], dtype="<u8")
            memory[arg] = np.unpackbits(row.view(np.uint8), bitorder="little")
        elif kind == "clear":
            memory[arg * dmd.rows_per_block:(arg + 1) * dmd.rows_per_block] = 0
        elif kind == "pulse":
            for b in arg:
                rows = slice(b * dmd.rows_per_block, (b + 1) * dmd.rows_per_block)
                mirrors[rows] = memory[rows]
            shown.append(mirrors.copy())
    return shown
