"""The received frame as its bytes pass, and capture of fixed headers from it."""

from amaranth import Signal
from amaranth.lib import wiring
from amaranth.lib.wiring import Out

from spec.wire import size

from ..wire import byte_slice, layout
from .layouts import OFFSET_BITS

__all__ = ["Tap", "capture"]


class Tap(wiring.Signature):
    """The received frame as its bytes pass, for the per-protocol checkers.

    Members
    -------
    valid : Out(1)
        ``data`` is byte ``offset`` of the frame, taken this cycle.
    data : Out(8)
    offset : Out(OFFSET_BITS)
        Position in the frame (0 = first byte of the destination MAC); saturates.
    length : Out(OFFSET_BITS)
        Length of the frame; valid once its last byte has passed, while the stack decides.
    """

    def __init__(self):
        super().__init__({
            "valid": Out(1),
            "data": Out(8),
            "offset": Out(OFFSET_BITS),
            "length": Out(OFFSET_BITS),
        })


def capture(m, tap, at, table, name):
    """A register holding the header ``table`` found at byte ``at`` of the frame, as a struct
    view (see :func:`gateware.wire.layout`). It loads as the bytes pass and keeps its
    value until the same offset of the next frame."""
    n = size(table)
    header = Signal(layout(table), name=name)
    for i in range(n):
        with m.If(tap.valid & (tap.offset == at + i)):
            m.d.sync += byte_slice(header.as_value(), n, i, 1).eq(tap.data)
    return header
