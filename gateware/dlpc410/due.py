"""Which due group goes first: the bus's pulse choice and the planner's questions about it.

A question over every group's flag would be a chain as long as the groups. Each flag vector is
registered beside its ``fours`` (bit q: some flag of ``flags[4q:4q + 4]``), so that every answer
here is a LUT or two deep whatever the number of groups.
"""

from amaranth import Cat, Mux

__all__ = ["fours_of", "lowest_due", "lowest_due_has"]


def fours_of(bits):
    """Bit q: some bit of ``bits[4q:4q + 4]`` is set (registered beside ``bits``, so that a
    question over every bit is a LUT or two of these, not a chain)."""
    return Cat(bits[lo:lo + 4].any() for lo in range(0, len(bits), 4))


def lowest_due(due, fours):
    """The lowest due group, one-hot (the pulse the bus chooses, when it may pulse): from the
    ``due`` flags and their ``fours`` (bit q: some flag of ``due[4q:4q + 4]``), so that no chain
    runs over every flag."""
    return Cat(due[g] & ~(due[g - g % 4:g].any() | fours[:g // 4].any()) for g in range(len(due)))


def lowest_due_has(due, fours, flags):
    """Whether the lowest due group (:func:`lowest_due`'s) has its bit of ``flags`` set: the
    lowest due quad's answer, each quad's from its own four groups (a priority choice at each
    level, so that the answer is two small choices deep, not a chain over every group)."""
    def first(bits, values):                  # the value at the lowest set bit (0: none set)
        out = 0
        for bit, value in reversed(list(zip(bits, values, strict=True))):
            out = Mux(bit, value, out)
        return out
    quads = [range(q, min(q + 4, len(due))) for q in range(0, len(due), 4)]
    return first([fours[i] for i in range(len(quads))],
                 [first([due[g] for g in quad], [flags[g] for g in quad]) for quad in quads])
