"""Wire formats as tables: a header is a list of ``(name, width in bits)`` in wire order.

The bottom of the tree: plain Python, imported by the gateware (which builds Amaranth views of
the same tables, :mod:`gateware.wire`), the host and the models. Fields are big-endian, first
field first on the wire; a table fills whole bytes.
"""

__all__ = ["size", "offsets", "pack", "unpack"]


def size(table):
    """Bytes on the wire."""
    bits = sum(width for _, width in table)
    assert bits % 8 == 0, "a record's fields fill whole bytes"
    return bits // 8


def offsets(table):
    """Field name -> byte offset of its first byte (fields that start on a byte boundary)."""
    out, bit = {}, 0
    for name, width in table:
        if bit % 8 == 0:
            out[name] = bit // 8
        bit += width
    return out


def pack(table, values):
    """``{name: int}`` -> big-endian bytes; missing fields are 0; unknown names are an error."""
    unknown = set(values) - {name for name, _ in table}
    if unknown:
        raise KeyError(f"fields not in the table: {sorted(unknown)}")
    acc = 0
    for name, width in table:
        value = int(values.get(name, 0))
        if not 0 <= value < (1 << width):
            raise ValueError(f"field {name}={value} does not fit {width} bits")
        acc = (acc << width) | value
    return acc.to_bytes(size(table), "big")


def unpack(table, raw):
    """Big-endian bytes (at least :func:`size` of them) -> ``{name: int}``."""
    n = size(table)
    if len(raw) < n:
        raise ValueError(f"need {n} bytes, got {len(raw)}")
    acc = int.from_bytes(bytes(raw[:n]), "big")
    out, shift = {}, n * 8
    for name, width in table:
        shift -= width
        out[name] = (acc >> shift) & ((1 << width) - 1)
    return out
