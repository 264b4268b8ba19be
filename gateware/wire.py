"""The tables of :mod:`spec` as Amaranth shapes: header layouts, their bytes, and the modes.

The bottom of the gateware: :mod:`spec` defines each wire format and mode once, in plain Python
(the host shares it); this module gives the gateware its views of them.
"""

import types

from amaranth import C, Cat, Value
from amaranth.lib import data, enum

from spec.wire import size

__all__ = ["layout", "view", "byte_slice", "to_bytes", "hdl_enum"]


def hdl_enum(modes, shape):
    """A :mod:`spec` mode (a Python ``IntEnum``) as an :class:`amaranth.lib.enum.Enum` with
    ``shape``: same names, same values; a field of this shape reads as an enum view."""
    def body(namespace):
        for member in modes:
            namespace[member.name] = member.value
        namespace["__doc__"] = modes.__doc__
    return types.new_class(modes.__name__, (enum.Enum,), {"shape": shape}, body)


def layout(table):
    """A :class:`amaranth.lib.data.StructLayout` with the table's fields.

    Fields are placed so that the Amaranth value ``Cat(byte[n-1], ..., byte[0])`` of the wire
    bytes (first byte most significant) reads as the struct: see :func:`view`.
    """
    return data.StructLayout(dict(reversed([(name, width) for name, width in table])))


def view(table, wire_bytes):
    """The struct view of ``wire_bytes`` (a list of 8-bit values, first byte on the wire first)."""
    assert len(wire_bytes) == size(table)
    return data.View(layout(table), Cat(*reversed(wire_bytes)))


def byte_slice(wide, total, first, count):
    """Bytes ``first .. first + count - 1`` (wire order) of a ``total``-byte value that holds
    its first wire byte in the most significant bits, as one value in the same order."""
    return wide[8 * (total - first - count):8 * (total - first)]


def to_bytes(table, values):
    """Wire bytes (8-bit Amaranth values, first first) of fields given as ``{name: value}``;
    values are truncated or zero-extended to the field width; missing fields are 0. Each byte
    is built from the field bits it holds, so that no byte drags the whole header along."""
    parts = []  # (lsb position in the big-endian integer, value), least significant first
    position = 0
    for name, width in reversed(table):
        value = Value.cast(values.get(name, 0))
        value = value[:width] if len(value) >= width else Cat(value, C(0, width - len(value)))
        parts.append((position, value))
        position += width
    n = size(table)
    out = []
    for i in range(n):
        lo, hi = 8 * (n - 1 - i), 8 * (n - i)
        pieces = [value[max(lo, at) - at:min(hi, at + len(value)) - at]
                  for at, value in parts if at < hi and at + len(value) > lo]
        out.append(Cat(*pieces))
    return out
