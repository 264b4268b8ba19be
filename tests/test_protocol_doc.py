"""docs/protocol.md lists the same fields, widths and offsets as spec/records.py."""

import re
from pathlib import Path

from spec import records, wire

DOC = Path(__file__).resolve().parents[1] / "docs" / "protocol.md"


def doc_rows():
    rows = re.findall(r"^\| (\d+) \| `(\w+)` \| (\d+) \|", DOC.read_text(), re.M)
    return [(int(offset), name, int(bits)) for offset, name, bits in rows]


def table_rows(table, start):
    out, bit = [], 8 * start
    for name, width in table:
        out.append((bit // 8, name, width))
        bit += width
    return out


def test_doc_tables_match_fields():
    header = wire.size(records.HEADER)
    # the page lists the master status reply after its network counters, which it says are the
    # status reply's, at the same offsets
    net = wire.size(records.NET_COUNTERS)
    assert records.STATUS_REPLY[:len(records.NET_COUNTERS)] == records.NET_COUNTERS
    assert records.MASTER_STATUS_REPLY[:len(records.NET_COUNTERS)] == records.NET_COUNTERS
    expected = (table_rows(records.HEADER, 0) + table_rows(records.IMAGE, header)
                + table_rows(records.DELTA, header)
                + table_rows(records.CONTROL, header) + table_rows(records.SEQUENCER, header)
                + table_rows(records.ENTRY, header) + table_rows(records.STATUS_REPLY, header)
                + table_rows(records.MASTER_CONTROL, header)
                + table_rows(records.MASTER_STATUS_REPLY[len(records.NET_COUNTERS):], header + net))
    assert doc_rows() == expected


def test_doc_headings_give_record_sizes():
    """Each record's heading says its whole size in bytes, header included."""
    sizes = {int(kind): int(size.replace(",", "")) for kind, size in
             re.findall(r"^### .*\(type (\d+), ([\d,]+) bytes\)$", DOC.read_text(), re.M)}
    kind = records.RecordType
    bodies = {kind.CONTROL: records.CONTROL, kind.SEQUENCER: records.SEQUENCER, kind.ENTRY: records.ENTRY,
              kind.STATUS_QUERY: [], kind.STATUS_REPLY: records.STATUS_REPLY,
              kind.MASTER_CONTROL: records.MASTER_CONTROL, kind.MASTER_STATUS: records.MASTER_STATUS_REPLY}
    assert sizes == {k: wire.size(records.HEADER) + wire.size(body) for k, body in bodies.items()}
