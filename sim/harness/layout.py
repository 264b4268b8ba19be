"""Packing and unpacking :mod:`amaranth.lib.data` layouts as integers, for cocotb.

A struct port of an Amaranth component becomes one flat vector in the generated Verilog; these
two functions let a cocotb testbench speak in field names, using the very layout the gateware
was built with.

Testbenches pack and unpack a payload per cycle, so plain values (dicts and lists of ints, nested
like the layout, every field given; fields of plain unsigned or signed shapes) are packed with
shifts and masks by the fields' offsets; anything else (an enum field, a missing field) goes
through the layout's own ``const``. Both give the same bits.
"""

from amaranth import Shape
from amaranth.lib import data

__all__ = ["pack", "unpack", "fields"]


class _NotPlain(Exception):
    """A shape or value the shifts and masks leave to the layout's ``const``."""


def pack(layout, value):
    """``value`` (a dict, list or int, nested like ``layout``) -> int."""
    layout = data.Layout.cast(layout)
    try:
        return _pack(layout, value)
    except _NotPlain:
        return layout.const(value).as_value().value


def unpack(layout, bits):
    """int -> nested dicts/lists of ints, by ``layout``'s field names."""
    layout = data.Layout.cast(layout)
    try:
        return _unpack(layout, int(bits))
    except _NotPlain:
        return _plain(data.Const(layout, int(bits)))


def _plain_width(shape):
    """The width of a plain unsigned or signed shape, with its signedness."""
    if isinstance(shape, int):
        return shape, False
    if isinstance(shape, Shape):
        return shape.width, shape.signed
    raise _NotPlain


def _pack(shape, value):
    if isinstance(shape, data.StructLayout):
        if not isinstance(value, dict) or value.keys() != shape.members.keys():
            raise _NotPlain
        return sum(_pack(field.shape, value[name]) << field.offset for name, field in shape)
    if isinstance(shape, data.ArrayLayout):
        if not isinstance(value, (list, tuple)) or len(value) != shape.length:
            raise _NotPlain
        width = Shape.cast(shape.elem_shape).width
        return sum(_pack(shape.elem_shape, item) << (i * width) for i, item in enumerate(value))
    width, _signed = _plain_width(shape)
    if not isinstance(value, int):
        raise _NotPlain
    return value & ((1 << width) - 1)


def _unpack(shape, bits):
    if isinstance(shape, data.StructLayout):
        return {name: _unpack(field.shape, bits >> field.offset) for name, field in shape}
    if isinstance(shape, data.ArrayLayout):
        width = Shape.cast(shape.elem_shape).width
        return [_unpack(shape.elem_shape, bits >> (i * width)) for i in range(shape.length)]
    width, signed = _plain_width(shape)
    bits &= (1 << width) - 1
    if signed and width and bits >> (width - 1):
        bits -= 1 << width
    return bits


def fields(layout):
    """``[(name, offset, mask)]`` of a flat struct layout: unpacking with shifts and masks, for
    values read every cycle."""
    layout = data.Layout.cast(layout)
    return [(name, field.offset, (1 << field.width) - 1) for name, field in layout]


def _plain(value):
    if isinstance(value, data.Const):
        layout = value.shape()
        if isinstance(layout, data.ArrayLayout):
            return [_plain(value[i]) for i in range(layout.length)]
        return {name: _plain(value[name]) for name, _field in layout}
    return int(value)
