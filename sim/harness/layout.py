"""Packing and unpacking :mod:`amaranth.lib.data` layouts as integers, for cocotb.

A struct port of an Amaranth component becomes one flat vector in the generated Verilog; these
two functions let a cocotb testbench speak in field names, using the very layout the gateware
was built with.
"""

from amaranth.lib import data

__all__ = ["pack", "unpack"]


def pack(layout, value):
    """``value`` (a dict, list or int, nested like ``layout``) -> int."""
    layout = data.Layout.cast(layout)
    return layout.const(value).as_value().value


def unpack(layout, bits):
    """int -> nested dicts/lists of ints, by ``layout``'s field names."""
    layout = data.Layout.cast(layout)
    return _plain(data.Const(layout, int(bits)))


def _plain(value):
    if isinstance(value, data.Const):
        layout = value.shape()
        if isinstance(layout, data.ArrayLayout):
            return [_plain(value[i]) for i in range(layout.length)]
        return {name: _plain(value[name]) for name, _field in layout}
    return int(value)
