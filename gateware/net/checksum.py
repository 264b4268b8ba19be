"""The Internet checksum (RFC 1071): ones' complement sums of 16-bit big-endian words."""

from amaranth import Const, Mux

__all__ = ["fold", "ones_sum", "word_add"]


def fold(total):
    """A wide two's complement sum of 16-bit words -> its 16-bit ones' complement sum.

    Two end-around carry folds suffice for sums of fewer than 65,537 words.
    """
    once = total[:16] + total[16:]
    return (once[:16] + once[16:])[:16]


def ones_sum(words):
    """Ones' complement sum of 16-bit values (Amaranth values or ints)."""
    total = Const(0, 16)
    for word in words:
        total = total + word
    return fold(total)


def word_add(accumulator, byte, high):
    """``accumulator`` plus ``byte`` taken as the high (``high`` true) or low half of a word."""
    return accumulator + Mux(high, byte << 8, byte)
