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
    expected = (table_rows(records.HEADER, 0) + table_rows(records.IMAGE, header)
                + table_rows(records.DELTA, header)
                + table_rows(records.CONTROL, header) + table_rows(records.SEQUENCER, header)
                + table_rows(records.ENTRY, header) + table_rows(records.STATUS_REPLY, header))
    assert doc_rows() == expected
