"""The plane order, in the arithmetic the sequencer's parts share.

A frame of ``depth`` planes shows its planes in the order of the registers: the exponent of the
plane at display position ``j`` (the plane of weight ``2**e``), and the stored plane it reads,
``e`` above the frame's lowest stored plane (the store's answer, worked out there from the
frame's depth and its sequence entry). Both are small tables (of ``depth`` and ``j``; of the
lowest plane and ``e``), written as lookups, not sums, so no carry chain is made for them. The
anchor register starts the order at a position of its own: ``(j + anchor) mod depth``, a
lookup too. In :attr:`~spec.registers.PlaneOrder.GROUPS` each group has a table of its own
(:func:`group_tables`), picked by the group a cycle before a position chooses from it.
"""

from amaranth import Array, Cat, Signal
from amaranth.lib import data

from ..registers import PlaneOrder

__all__ = ["order_position", "group_tables", "exponents", "stored_plane"]


def _table(function, rows=16, columns=8):
    """``function(a, j)`` as a lookup on ``a`` (0..rows-1) and ``j`` (0..columns-1), 3-bit
    results."""
    return Array(Array(function(a, j) & 7 for j in range(columns)) for a in range(rows))


_MSB_FIRST = _table(lambda depth, j: depth - 1 - j)


#: The order's position shown at display position ``j`` from the ``anchor``: ``(j + anchor) mod
#: depth``, a lookup on ``depth`` and ``j + anchor`` (0..14).
_ROTATED = _table(lambda depth, at: at % depth if depth else at, columns=16)

#: ``j + anchor`` (0..14) as a lookup on both (each bit one function of six bits), so that no
#: carry chain comes before the rotation's lookup.
_SUM = Array(Array(j + anchor for anchor in range(8)) for j in range(8))


def order_position(m, regs, j, depth, name):
    """The position in the plane order of ``regs`` that display position ``j`` of a frame of
    ``depth`` planes shows: ``j`` counted from the ``anchor`` register, modulo ``depth``. (Its
    callers register it, with :func:`exponents`, before it chooses an exponent: the lookups
    together are too deep for a cycle.)"""
    k = Signal(3, name=name)
    m.d.comb += k.eq(_ROTATED[depth][_SUM[j][regs.anchor]])
    return k


def group_tables(regs, groups):
    """Each of ``groups`` groups' order table (eight 3-bit exponents) in ``regs``, an
    :class:`~amaranth.hdl.Array` to index by group (and register: a wide choice)."""
    return Array(Cat(regs.group_tables[8 * g + j] for j in range(8)) for g in range(groups))


def exponents(m, regs, depth, name, table):
    """The weight exponent at each position ``k`` (0..7) of the plane order of ``regs`` (a
    :class:`~gateware.registers.Registers` view) in a frame of ``depth`` planes (in GROUPS,
    ``table``'s: the group's, from :func:`group_tables`, registered): lookups on ``depth``
    alone, to be registered before a position chooses one."""
    each = Signal(data.ArrayLayout(3, 8), name=name)
    with m.Switch(regs.order):
        with m.Case(PlaneOrder.MSB_FIRST):
            m.d.comb += [each[k].eq(_MSB_FIRST[depth][k]) for k in range(8)]
        with m.Case(PlaneOrder.LSB_FIRST):
            m.d.comb += [each[k].eq(k) for k in range(8)]
        with m.Case(PlaneOrder.TABLE):
            m.d.comb += each.eq(regs.order_table)
        with m.Case(PlaneOrder.GROUPS):
            m.d.comb += each.eq(table)
    return each


_STORED = _table(lambda low_plane, e: low_plane + e, rows=8)


def stored_plane(low_plane, e):
    """The stored plane (0..7) of exponent ``e`` in a frame whose least significant plane is
    stored plane ``low_plane``: ``low_plane + e``."""
    return _STORED[low_plane][e]
