"""The sequencer's run-time registers as an Amaranth struct, and its modes as enums.

Built from :data:`spec.registers.FIELDS` (the one definition the host and the protocol share):
:data:`Registers` has a field per register in the same order and width, an enum field reads as a
view of the mode below, ``order_table`` as an array of eight 3-bit exponents.
"""

import types

from amaranth import Cat
from amaranth.lib import data

from spec import registers as spec

from .wire import hdl_enum

__all__ = ["ResetMode", "PlaneOrder", "TriggerMode", "Source", "Registers", "wire_registers",
           "TIME_BITS", "LSB_BITS", "DURATION_BITS"]

TIME_BITS, LSB_BITS, DURATION_BITS = spec.TIME_BITS, spec.LSB_BITS, spec.DURATION_BITS

ResetMode = hdl_enum(spec.ResetMode, 2)
PlaneOrder = hdl_enum(spec.PlaneOrder, 2)
TriggerMode = hdl_enum(spec.TriggerMode, 2)
Source = hdl_enum(spec.Source, 1)
_MODES = {spec.ResetMode: ResetMode, spec.PlaneOrder: PlaneOrder, spec.TriggerMode: TriggerMode,
          spec.Source: Source}


def _shape(field):
    if field.enum is not None:
        return _MODES[field.enum]
    if field.count:
        return data.ArrayLayout(field.width, field.count)
    return field.width


def _registers(namespace):
    namespace["__annotations__"] = {f.name: _shape(f) for f in spec.FIELDS}
    namespace["__doc__"] = "The sequencer's run-time registers (all durations in ``dmd`` cycles).\n\n" + \
        "\n".join(f"{f.name}: {f.doc}" for f in spec.FIELDS)


#: The register set, a :class:`~amaranth.lib.data.Struct` (:data:`spec.registers.FIELDS` gives
#: each field's meaning).
Registers = types.new_class("Registers", (data.Struct,), {}, _registers)


def wire_registers(wire):
    """The sequencer record's fields (a struct view of :data:`spec.records.SEQUENCER`) as the
    bits of a :data:`Registers` value (high bits beyond each field dropped)."""
    return Cat(wire[f.name][:f.bits] for f in spec.FIELDS)
