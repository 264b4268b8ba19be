"""The plane order, in the arithmetic the sequencer's parts share.

A frame of ``depth`` planes shows its planes in the order of the registers: the exponent of the
plane at display position ``j`` (the plane of weight ``2**e``), and the stored plane it reads,
``e`` above the frame's lowest stored plane (the store's answer, worked out there from the
frame's depth and its sequence entry). Both are small tables (of ``depth`` and ``j``; of the
lowest plane and ``e``), written as lookups, not sums, so no carry chain is made for them.
"""

from amaranth import Array, Signal

from ..registers import PlaneOrder

__all__ = ["exponent", "stored_plane"]


def _table(function, rows=16):
    """``function(a, j)`` as a lookup on ``a`` (0..rows-1) and ``j`` (0..7), 3-bit results."""
    return Array(Array(function(a, j) & 7 for j in range(8)) for a in range(rows))


_MSB_FIRST = _table(lambda depth, j: depth - 1 - j)


def exponent(m, regs, j, depth, name):
    """Weight exponent of display position ``j`` in a frame of ``depth`` planes, under the plane
    order of ``regs`` (a :class:`~gateware.registers.Registers` view)."""
    e = Signal(3, name=name)
    with m.Switch(regs.order):
        with m.Case(PlaneOrder.MSB_FIRST):
            m.d.comb += e.eq(_MSB_FIRST[depth][j])
        with m.Case(PlaneOrder.LSB_FIRST):
            m.d.comb += e.eq(j)
        with m.Default():
            m.d.comb += e.eq(regs.order_table[j])
    return e


_STORED = _table(lambda low_plane, e: low_plane + e, rows=8)


def stored_plane(low_plane, e):
    """The stored plane (0..7) of exponent ``e`` in a frame whose least significant plane is
    stored plane ``low_plane``: ``low_plane + e``."""
    return _STORED[low_plane][e]
