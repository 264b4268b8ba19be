"""Encoding and decoding of the application records (``docs/protocol.md``)."""

import numpy as np

from spec import records, wire
from spec.records import Action, RecordType

__all__ = ["ProtocolError", "header", "image_record", "image_records", "changed_rows", "sequence_records",
           "pixels_per_record", "control_record", "sequencer_record", "entry_record", "status_query",
           "status_reply", "master_control_record", "master_status_reply", "decode",
           "SEQUENCE_MASK", "DEFAULT_LIMIT"]

#: Record sequence numbers wrap at this mask.
SEQUENCE_MASK = (1 << dict(records.HEADER)["sequence"]) - 1
#: Records fit an ordinary 1500-byte MTU unless the caller says otherwise.
DEFAULT_LIMIT = records.record_limit(1500)


class ProtocolError(ValueError):
    """Bytes that are not a well-formed record of this protocol version."""


def header(record_type, sequence):
    return wire.pack(records.HEADER, {"magic": records.MAGIC, "version": records.VERSION,
                                       "type": record_type, "sequence": sequence & SEQUENCE_MASK})


def pixels_per_record(limit=DEFAULT_LIMIT, *, delta=False):
    """Pixels an image record of at most ``limit`` bytes carries: 1,462 in a 1500-byte MTU,
    8,962 in a 9,000-byte one; a delta record, four fewer (it names its base and row count)."""
    pixels = limit - (records.DELTA_HEADER if delta else records.IMAGE_HEADER)
    if pixels < 1:
        raise ValueError(f"a {limit}-byte record has no room for pixels")
    return pixels


def image_record(frame, offset, pixels, sequence=0, *, base=0, carried=0):
    """One record of ``pixels`` (bytes) of frame ``frame`` from position ``offset``: an image
    record of a whole frame, or (``carried`` rows, not 0) a delta record naming its ``base``."""
    if carried:
        body = wire.pack(records.DELTA, {"frame": frame & 0xFFFF, "base": base & 0xFFFF, "carried": carried,
                                         "offset": offset})
        return header(RecordType.DELTA, sequence) + body + bytes(pixels)
    body = wire.pack(records.IMAGE, {"frame": frame & 0xFFFF, "offset": offset})
    return header(RecordType.IMAGE, sequence) + body + bytes(pixels)


def changed_rows(image, reference):
    """Indices of the rows in which two images (same shape) differ: what a delta of ``reference``
    must carry to show ``image``."""
    image, reference = np.asarray(image), np.asarray(reference)
    if image.shape != reference.shape:
        raise ValueError(f"images of shapes {image.shape} and {reference.shape} have no rows in common")
    return np.flatnonzero((image != reference).any(axis=1))


def _runs(rows):
    """Sorted distinct row indices -> ``(first, end)`` of each run of consecutive rows."""
    cuts = np.flatnonzero(np.diff(rows) != 1) + 1
    return [(int(run[0]), int(run[-1]) + 1) for run in np.split(rows, cuts)]


def image_records(image, frame, *, sequence=0, limit=DEFAULT_LIMIT, pixels=None, base=None, rows=None):
    """An 8-bit image (``uint8`` array, rows x columns) -> its image records: its pixels row by
    row, each record as many as fit ``limit`` bytes (or ``pixels``), so that rows split across
    records anywhere. Sequence numbers count up from ``sequence``.

    Parameters
    ----------
    base : int, optional
        Send a delta frame of whole frame ``base`` (which the projector holds): only ``rows``.
    rows : array_like of int, optional
        With ``base``: the rows the delta carries (any order, repeats ignored; at least one).
        Each run of consecutive rows goes as consecutive records, cut as a whole frame's are;
        the projector takes every other row from ``base``.
    """
    image = np.asarray(image)
    if image.dtype != np.uint8 or image.ndim != 2:
        raise ValueError(f"need a 2-D uint8 image, got {image.dtype} with shape {image.shape}")
    if (base is None) != (rows is None):
        raise ValueError("a delta frame needs both its base and its rows")
    height, columns = image.shape
    if rows is None:
        runs, carried, base = [(0, height)], 0, 0      # a whole frame: one run of every row
    else:
        rows = np.unique(np.asarray(rows, dtype=np.int64))
        if not rows.size or rows[0] < 0 or rows[-1] >= height:
            raise ValueError(f"a delta carries 1 to {height} rows of the image, got {rows.tolist()}")
        runs, carried = _runs(rows), rows.size
    flat = np.ascontiguousarray(image).reshape(-1).tobytes()
    step = pixels or pixels_per_record(limit, delta=bool(carried))
    spans = [(offset, min(offset + step, end * columns))
             for first, end in runs for offset in range(first * columns, end * columns, step)]
    return [image_record(frame, start, flat[start:stop], sequence + i, base=base, carried=carried)
            for i, (start, stop) in enumerate(spans)]


def sequence_records(images, first_frame=0, *, sequence=0, limit=DEFAULT_LIMIT):
    """Several images, frame ids counting up from ``first_frame``."""
    out = []
    for i, image in enumerate(images):
        out += image_records(image, first_frame + i, sequence=sequence + len(out), limit=limit)
    return out


def _settings_record(record_type, table, fields, sequence, action, config):
    """A record of ``table`` (``apply``, ``action``, then the ``fields`` table) that sets the
    given ``config`` fields, its ``apply`` bit i set for each given field i, and does ``action``."""
    names = [name for name, _ in fields]
    unknown = set(config) - set(names)
    if unknown:
        raise KeyError(f"not a configuration field: {sorted(unknown)}")
    apply = sum(1 << names.index(name) for name in config)
    body = wire.pack(table, {"apply": apply, "action": int(action), **config})
    return header(record_type, sequence) + body


def control_record(sequence=0, *, software_trigger=False, sequence_start=False, **config):
    """A control record setting the given :data:`~spec.records.CONFIG` fields
    (others unchanged) and optionally firing a software trigger or playing the sequence's
    entries from the first (``sequence_start``, after the fields are set)."""
    action = (Action.SOFTWARE_TRIGGER if software_trigger else 0) | (Action.SEQUENCE_START if sequence_start else 0)
    return _settings_record(RecordType.CONTROL, records.CONTROL, records.CONFIG, sequence, action, config)


def master_control_record(sequence=0, *, software_trigger=False, **config):
    """A sync master's control record setting the given :data:`~spec.records.MASTER_CONFIG`
    fields (others unchanged; times in the master's cycles) and optionally firing a software
    trigger after they are set. The master drops a record whose configuration it cannot take
    (:func:`spec.records.master_config_faults`, checked by :meth:`host.client.MasterClient.configure`)."""
    action = Action.SOFTWARE_TRIGGER if software_trigger else 0
    return _settings_record(RecordType.MASTER_CONTROL, records.MASTER_CONTROL, records.MASTER_CONFIG, sequence,
                            action, config)


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
        faults = records.register_faults(fields, dmd, beats)
        failed = [check for check, bad in faults.items() if bad]
        if failed:
            raise ValueError(f"the sequencer cannot obey this register set: {', '.join(failed)}")
    body = wire.pack(records.SEQUENCER, fields)
    return header(RecordType.SEQUENCER, sequence) + body


def entry_record(index, slot, sequence=0, *, lsb=0, dark=0, follow=False, camera=True, depth=0, skip=0):
    """A sequence entry record: entry ``index`` shows the frame of ``slot`` with a least
    significant plane of ``lsb`` cycles (0: the sequencer's register), at least ``dark`` cycles
    dark after it before a frame that follows it, following the frame before it with no trigger
    (``follow``) or waiting for one, with a camera trigger or none, at ``depth`` bits: its
    frame's most significant planes after leaving out ``skip`` of them (``depth`` 0: all the
    frame has below those). Raises :class:`ValueError` on what the projector would drop
    (:func:`spec.records.entry_faults`, but the slot's check against the sequence in force);
    whether the planes are in the frame is the projector's to see when the entry plays (it skips
    the entry if not: :meth:`host.client.Client.play_sequence` checks it against the frames)."""
    fields = {"index": index, "slot": slot, "lsb": lsb, "dark": dark, "follow": int(follow),
              "camera_off": int(not camera), "depth": depth, "skip": skip}
    failed = [check for check, bad in records.entry_faults(fields, 1 << 8).items() if bad]
    if failed:
        raise ValueError(f"the projector cannot take this entry: {', '.join(failed)}")
    return header(RecordType.ENTRY, sequence) + wire.pack(records.ENTRY, fields)


def status_query(sequence=0):
    return header(RecordType.STATUS_QUERY, sequence)


def status_reply(sequence, values):
    """A status reply record (what the gateware sends; used by test servers)."""
    return header(RecordType.STATUS_REPLY, sequence) + wire.pack(records.STATUS_REPLY, values)


def master_status_reply(sequence, values):
    """A sync master's status reply record (what its gateware sends; used by test servers)."""
    return header(RecordType.MASTER_STATUS, sequence) + wire.pack(records.MASTER_STATUS_REPLY, values)


_BODIES = {
    RecordType.IMAGE: records.IMAGE,
    RecordType.DELTA: records.DELTA,
    RecordType.CONTROL: records.CONTROL,
    RecordType.STATUS_QUERY: [],
    RecordType.STATUS_REPLY: records.STATUS_REPLY,
    RecordType.SEQUENCER: records.SEQUENCER,
    RecordType.ENTRY: records.ENTRY,
    RecordType.MASTER_CONTROL: records.MASTER_CONTROL,
    RecordType.MASTER_STATUS: records.MASTER_STATUS_REPLY,
}


def decode(raw):
    """A record's bytes (a whole UDP payload) -> ``(header, body, rest)``: two dicts and the
    bytes after the body (an image or delta record's pixels). Raises :class:`ProtocolError` on anything
    malformed."""
    raw = bytes(raw)
    n = wire.size(records.HEADER)
    if len(raw) < n:
        raise ProtocolError(f"{len(raw)} bytes is shorter than a record header ({n})")
    head = wire.unpack(records.HEADER, raw)
    if head["magic"] != records.MAGIC:
        raise ProtocolError(f"magic 0x{head['magic']:04x} is not 0x{records.MAGIC:04x}")
    if head["version"] != records.VERSION:
        raise ProtocolError(f"protocol version {head['version']}, this client speaks {records.VERSION}")
    try:
        kind = RecordType(head["type"])
    except ValueError:
        raise ProtocolError(f"unknown record type {head['type']}") from None
    table = _BODIES[kind]
    size = n + wire.size(table)
    pixels = kind in (RecordType.IMAGE, RecordType.DELTA)
    if len(raw) < size + pixels:
        raise ProtocolError(f"record type {head['type']} needs {size + pixels} bytes, got {len(raw)}")
    if not pixels and len(raw) != size:
        raise ProtocolError(f"record type {head['type']} is {size} bytes, got {len(raw)}")
    body = wire.unpack(table, raw[n:]) if table else {}
    return head, body, raw[size:]
