"""The protocol's field tables: host encoder and gateware layouts agree, records round-trip."""

import itertools

import numpy as np
import pytest
from amaranth import C, Const
from amaranth.lib import data

from gateware.wire import layout, to_bytes, view
from host import codec
from spec import records, wire


def test_pack_unpack_round_trip():
    values = {name: (i * 0x9E3779B1) & ((1 << width) - 1) for i, (name, width) in enumerate(records.CONTROL)}
    raw = wire.pack(records.CONTROL, values)
    assert len(raw) == wire.size(records.CONTROL)
    assert wire.unpack(records.CONTROL, raw) == values


def test_pack_rejects_bad_values():
    with pytest.raises(ValueError):
        wire.pack(records.HEADER, {"version": 256})
    with pytest.raises(KeyError):
        wire.pack(records.HEADER, {"colour": 1})


@pytest.mark.parametrize("table", [records.HEADER, records.IMAGE, records.DELTA, records.CONTROL,
                                   records.STATUS_REPLY])
def test_gateware_view_reads_host_bytes(table):
    """The struct view the gateware puts on received bytes reads what the host packed, and the
    bytes the gateware writes are what the host unpacks."""
    values = {name: (7 + 31 * i) % (1 << width) for i, (name, width) in enumerate(table)}
    raw = wire.pack(table, values)
    seen = view(table, [C(b, 8) for b in raw])
    for name, _ in table:
        assert Const.cast(seen[name]).value == values[name], name
    sent = to_bytes(table, values)
    assert bytes(Const.cast(b).value for b in sent) == raw
    assert isinstance(layout(table), data.StructLayout)


@pytest.mark.parametrize("mtu, pixels", [(1500, 1462), (9000, 8962)])
def test_record_sizes_fill_the_mtu(mtu, pixels):
    """A record fills the MTU less the IPv4 and UDP headers; its own header is 10 bytes for a
    whole frame's image record, 14 for a delta record (which names its base and row count)."""
    assert (records.IMAGE_HEADER, records.DELTA_HEADER) == (10, 14)
    limit = records.record_limit(mtu)
    assert limit == mtu - 28
    assert codec.pixels_per_record(limit) == pixels and codec.pixels_per_record(limit, delta=True) == pixels - 4
    image = np.arange(16 * 1024, dtype=np.uint32).astype(np.uint8).reshape(16, 1024)
    assert len(codec.image_records(image, 0, limit=limit)[0]) == limit
    assert len(codec.image_records(image, 1, limit=limit, base=0, rows=range(16))[0]) == limit


@pytest.mark.parametrize("mtu", [1500, 9000])
def test_image_records_round_trip(mtu):
    image = np.random.default_rng(0).integers(0, 256, (768, 1024), dtype=np.uint8)
    encoded = codec.image_records(image, frame=5, sequence=250, limit=records.record_limit(mtu))
    assert len(encoded) == -(-image.size // codec.pixels_per_record(records.record_limit(mtu)))
    rebuilt = bytearray(image.size)
    for i, record in enumerate(encoded):
        head, body, pixels = codec.decode(record)
        assert head["sequence"] == (250 + i) % 256 and head["type"] == records.RecordType.IMAGE
        assert body["frame"] == 5 and len(record) <= records.record_limit(mtu)
        rebuilt[body["offset"]:body["offset"] + len(pixels)] = pixels
    assert bytes(rebuilt) == image.tobytes()


@pytest.mark.parametrize("pixels", [100, 1024, codec.pixels_per_record(records.record_limit(1500), delta=True)])
def test_delta_records_carry_the_changed_rows(pixels):
    """A delta frame's records carry exactly the rows that differ from its base, each run of
    consecutive rows in consecutive records (rows split as a whole frame's), every record naming
    the base and the count of distinct rows; pasted over the base they give the new image."""
    rng = np.random.default_rng(7)
    old = rng.integers(0, 256, (768, 1024), dtype=np.uint8)
    changed = sorted({0, 1, 2, 767, *rng.choice(np.arange(3, 767), 40, replace=False).tolist()})
    new = old.copy()
    new[changed, rng.integers(0, 1024, len(changed))] ^= rng.integers(1, 256, len(changed), dtype=np.uint8)
    rows = codec.changed_rows(new, old)
    assert rows.tolist() == np.nonzero((new != old).any(axis=1))[0].tolist() == changed
    encoded = codec.image_records(new, frame=9, base=4, rows=rows[::-1], sequence=254, pixels=pixels)
    rebuilt, carried, end = old.reshape(-1).copy(), set(), None
    for i, record in enumerate(encoded):
        head, body, data = codec.decode(record)
        assert head["sequence"] == (254 + i) % 256 and (body["frame"], body["base"], body["carried"]) == (9, 4, 44)
        assert len(data) <= pixels
        first, last = body["offset"] // 1024, (body["offset"] + len(data) - 1) // 1024
        # a record continues the previous one, or starts a run: a row no record before carried
        assert body["offset"] == end or (body["offset"] % 1024 == 0 and first - 1 not in carried)
        rebuilt[body["offset"]:body["offset"] + len(data)] = np.frombuffer(data, np.uint8)
        carried |= set(range(first, last + 1))
        end = body["offset"] + len(data)
    assert sorted(carried) == changed and (rebuilt.reshape(new.shape) == new).all()
    runs = [len(list(run)) for _, run in itertools.groupby(enumerate(changed), lambda r: r[1] - r[0])]
    assert len(encoded) == sum(-(-n * 1024 // pixels) for n in runs)


def test_whole_frame_records_name_no_base():
    """A whole frame goes as image records (type 1: no base, no row count), a delta as delta
    records (type 7)."""
    decoded = [codec.decode(record) for record in codec.image_records(np.ones((4, 8), np.uint8), 3, pixels=5)]
    assert [(h["type"], b) for h, b, _ in decoded] == \
        [(records.RecordType.IMAGE, {"frame": 3, "offset": 5 * i}) for i in range(7)]
    delta = codec.image_records(np.ones((4, 8), np.uint8), 4, pixels=5, base=3, rows=[2])
    assert [codec.decode(record)[0]["type"] for record in delta] == [records.RecordType.DELTA] * 2


@pytest.mark.parametrize("kwargs, message", [
    ({"base": 2}, "both its base and its rows"),
    ({"rows": [1]}, "both its base and its rows"),
    ({"base": 2, "rows": []}, "1 to 4 rows"),
    ({"base": 2, "rows": [4]}, "1 to 4 rows"),
    ({"base": 2, "rows": [-1]}, "1 to 4 rows"),
])
def test_bad_delta(kwargs, message):
    with pytest.raises(ValueError, match=message):
        codec.image_records(np.zeros((4, 8), np.uint8), 3, **kwargs)


def test_frame_ids_in_serial_number_order():
    assert records.frame_newer(1, 0) and records.frame_newer(0, 0xFFFF) and records.frame_newer(0x7FFF, 0)
    assert not records.frame_newer(0, 0) and not records.frame_newer(0x8000, 0) and not records.frame_newer(0, 5)


def test_control_record_selects_fields():
    head, body, _ = codec.decode(codec.control_record(3, armed=1, port=7000, software_trigger=True))
    names = [name for name, _ in records.CONFIG]
    assert body["apply"] == (1 << names.index("armed")) | (1 << names.index("port"))
    assert body["action"] == records.Action.SOFTWARE_TRIGGER
    assert (body["armed"], body["port"], head["sequence"]) == (1, 7000, 3)
    with pytest.raises(KeyError):
        codec.control_record(exposure=3)


@pytest.mark.parametrize("mutate, message", [
    (lambda r: r[:4], "shorter than a record header"),
    (lambda r: b"XX" + r[2:], "magic"),
    (lambda r: r[:2] + bytes([records.VERSION + 1]) + r[3:], "version"),
    (lambda r: r + b"\0", "is 5 bytes, got 6"),
    (lambda r: r[:3] + bytes([77]) + r[4:], "unknown record type"),
])
def test_decode_rejects_malformed(mutate, message):
    with pytest.raises(codec.ProtocolError, match=message):
        codec.decode(mutate(codec.status_query(1)))


def test_bad_image_input():
    with pytest.raises(ValueError):
        codec.image_records(np.zeros((4, 4), np.uint16), 0)
