"""Cycle arithmetic the sequencer's parts share: the time base and the plane order.

Times are cycles of the free-running ``now`` counter (:data:`gateware.registers.TIME_BITS`
wide); comparisons are made on differences, so the base may wrap.
"""

from amaranth import Signal

from ..registers import TIME_BITS, PlaneOrder

__all__ = ["diff", "exponent"]


def diff(a, b):
    """``a - b`` as a signed time difference (the time base may wrap)."""
    return (a - b)[:TIME_BITS].as_signed()


def exponent(m, regs, j, depth, name):
    """Weight exponent of display position ``j`` in a frame of ``depth`` planes, under the plane
    order of ``regs`` (a :class:`~gateware.registers.Registers` view)."""
    e = Signal(3, name=name)
    with m.Switch(regs.order):
        with m.Case(PlaneOrder.MSB_FIRST):
            m.d.comb += e.eq(depth - 1 - j)
        with m.Case(PlaneOrder.LSB_FIRST):
            m.d.comb += e.eq(j)
        with m.Default():
            m.d.comb += e.eq(regs.order_table[j])
    return e
