"""Encoding and decoding of the application records (``docs/protocol.md``)."""

import numpy as np

from spec import records, wire
from spec.records import Action, RecordType
from spec.schedule import row_cycles

__all__ = ["ProtocolError", "header", "image_records", "sequence_records", "rows_per_record",
           "control_record", "sequencer_record", "status_query", "status_reply", "decode"]


class ProtocolError(ValueError):
    """Bytes that are not a well-formed record of this protocol version."""


def header(record_type, length, sequence):
    return wire.pack(records.HEADER, {"magic": records.MAGIC, "version": records.VERSION,
                                       "type": record_type, "length": length,
                                       "sequence": sequence & 0xFFFFFFFF})


def rows_per_record(row_bytes, limit=records.MAX_RECORD):
    """Whole rows that fit one record: 8 rows of 1,024 bytes or 4 of 2,048 in a 9,000-byte MTU."""
    rows = (limit - records.image_record_length(0, row_bytes)) // row_bytes
    if rows < 1:
        raise ValueError(f"a {row_bytes}-byte row does not fit a {limit}-byte record")
    # Keep to a power of two so that records of a frame are all the same size.
    return 1 << (rows.bit_length() - 1)


def image_records(image, frame, *, sequence=0, rows=None):
    """An 8-bit image (``uint8`` array, rows x columns) -> its image records, top to bottom.

    ``rows`` is the rows per record (default :func:`rows_per_record`). Sequence numbers count
    up from ``sequence``.
    """
    image = np.asarray(image)
    if image.dtype != np.uint8 or image.ndim != 2:
        raise ValueError(f"need a 2-D uint8 image, got {image.dtype} with shape {image.shape}")
    height, width = image.shape
    rows = rows or rows_per_record(width)
    out = []
    for first in range(0, height, rows):
        block = image[first:first + rows]
        body = wire.pack(records.IMAGE, {"frame": frame & 0xFFFF, "first_row": first,
                                          "row_count": len(block), "row_bytes": width})
        length = records.image_record_length(len(block), width)
        out.append(header(RecordType.IMAGE, length, sequence + len(out)) + body + block.tobytes())
    return out


def sequence_records(images, first_frame=0, *, sequence=0, rows=None):
    """Several images, frame ids counting up from ``first_frame``."""
    out = []
    for i, image in enumerate(images):
        out += image_records(image, first_frame + i, sequence=sequence + len(out), rows=rows)
    return out


def control_record(sequence=0, *, software_trigger=False, **config):
    """A control record setting the given :data:`~spec.records.CONFIG` fields
    (others unchanged) and optionally firing a software trigger."""
    names = [name for name, _ in records.CONFIG]
    unknown = set(config) - set(names)
    if unknown:
        raise KeyError(f"not a configuration field: {sorted(unknown)}")
    apply = sum(1 << names.index(name) for name in config)
    action = Action.SOFTWARE_TRIGGER if software_trigger else 0
    body = wire.pack(records.CONTROL, {"apply": apply, "action": int(action), **config})
    return header(RecordType.CONTROL, wire.size(records.HEADER) + len(body), sequence) + body


def sequencer_record(registers, sequence=0, *, dmd=None, beats=1):
    """A sequencer record carrying a whole register set: ``registers`` as
    :meth:`spec.schedule.Params.registers` gives it (from
    :func:`spec.schedule.plan`), or already as wire values (ints).

    With ``dmd``, the set is first checked as the projector will check it
    (:func:`spec.records.register_faults`); a set it would drop raises
    :class:`ValueError` naming the failed checks."""
    names = [name for name, _ in records.SEQUENCER]
    fields = registers if all(isinstance(registers.get(n), int) for n in names) \
        else records.register_wire(registers)
    if dmd is not None:
        failed = [check for check, bad in records.register_faults(fields, row_cycles(dmd, beats)).items() if bad]
        if failed:
            raise ValueError(f"the sequencer cannot obey this register set: {', '.join(failed)}")
    body = wire.pack(records.SEQUENCER, fields)
    return header(RecordType.SEQUENCER, wire.size(records.HEADER) + len(body), sequence) + body


def status_query(sequence=0):
    return header(RecordType.STATUS_QUERY, wire.size(records.HEADER), sequence)


def status_reply(sequence, values):
    """A status reply record (what the gateware sends; used by test servers)."""
    body = wire.pack(records.STATUS_REPLY, values)
    return header(RecordType.STATUS_REPLY, wire.size(records.HEADER) + len(body), sequence) + body


_BODIES = {
    RecordType.IMAGE: records.IMAGE,
    RecordType.CONTROL: records.CONTROL,
    RecordType.STATUS_QUERY: [],
    RecordType.STATUS_REPLY: records.STATUS_REPLY,
    RecordType.SEQUENCER: records.SEQUENCER,
}


def decode(raw):
    """A record's bytes -> ``(header, body, rest)``: two dicts and the bytes after the body
    (an image record's pixels). Raises :class:`ProtocolError` on anything malformed."""
    raw = bytes(raw)
    n = wire.size(records.HEADER)
    if len(raw) < n:
        raise ProtocolError(f"{len(raw)} bytes is shorter than a record header ({n})")
    head = wire.unpack(records.HEADER, raw)
    if head["magic"] != records.MAGIC:
        raise ProtocolError(f"magic 0x{head['magic']:04x} is not 0x{records.MAGIC:04x}")
    if head["version"] != records.VERSION:
        raise ProtocolError(f"protocol version {head['version']}, this client speaks {records.VERSION}")
    if head["length"] != len(raw):
        raise ProtocolError(f"record says {head['length']} bytes, datagram has {len(raw)}")
    try:
        table = _BODIES[RecordType(head["type"])]
    except ValueError:
        raise ProtocolError(f"unknown record type {head['type']}") from None
    if len(raw) < n + wire.size(table):
        raise ProtocolError(f"record type {head['type']} needs {n + wire.size(table)} bytes")
    body = wire.unpack(table, raw[n:]) if table else {}
    return head, body, raw[n + wire.size(table):]
