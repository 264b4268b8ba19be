"""Wide sums and comparisons in limbs of :data:`LIMB_BITS`, a limb a registered stage, so that
a limb's sum with its carry in and out fills one carry chain of 16 bits, and no path goes
through two of them.

They suit values that hold still while the result is read (register settings, a group's plane),
or that are carried along a pipeline a stage at a time.
"""

from amaranth import Cat, Signal

__all__ = ["LIMB_BITS", "limbs", "pipelined_sum", "limb_order", "greater"]

#: Bits of a limb: with its carry out, 16 (four CARRY4 cells).
LIMB_BITS = 15


def limbs(width):
    """``(lo, hi)`` of each limb of a ``width``-bit value, least significant first."""
    return [(lo, min(lo + LIMB_BITS, width)) for lo in range(0, width, LIMB_BITS)]


def pipelined_sum(m, a, b, carry_in, name):
    """``a + b + carry_in``, one limb a stage: ``a[k]`` is the first operand on stage ``k``
    (``a[0]`` registered a cycle before the first limb is added; one copy per limb, or the same
    value for one that holds still), ``b(k)`` the second operand as formed on stage ``k``. Returns
    the sum, one bit wider, on the register after the last limb's (the earlier limbs delayed to
    it), and the top limb's carry out (the sum's top bit)."""
    width = len(a[0])
    parts, carry = [], carry_in
    assert len(limbs(width)) == len(a)
    for k, (lo, hi) in enumerate(limbs(width)):
        part = Signal(hi - lo + 1, name=f"{name}_{k}")
        m.d.sync += part.eq(a[k][lo:hi] + b(k)[lo:hi] + carry)
        carry = part[-1]
        # the earlier limbs wait for the last
        for i, earlier in enumerate(parts):
            later = Signal(len(earlier), name=f"{name}_{i}_{k}")
            m.d.sync += later.eq(earlier)
            parts[i] = later
        parts.append(part)
    return Cat(*(p[:-1] for p in parts[:-1]), parts[-1]), parts[-1][-1]


def limb_order(m, a, b, name):
    """Per limb of ``a`` and ``b`` (of one width): registered ``(above, same)`` flags."""
    spans = limbs(len(a))
    above, same = Signal(len(spans), name=f"{name}_above"), Signal(len(spans), name=f"{name}_same")
    m.d.sync += [above.eq(Cat(a[lo:hi] > b[lo:hi] for lo, hi in spans)),
                 same.eq(Cat(a[lo:hi] == b[lo:hi] for lo, hi in spans))]
    return above, same


def greater(above, same, *, or_equal=False):
    """``a > b`` (``a >= b``) from :func:`limb_order`'s flags."""
    result = 1 if or_equal else 0
    for i in range(len(above)):
        result = above[i] | (same[i] & result)
    return result
