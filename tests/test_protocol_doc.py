"""docs/protocol.md lists the same fields, widths and offsets as gateware/protocol/fields.py."""

import re
from pathlib import Path

from gateware.protocol import fields

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
    header = fields.size(fields.HEADER)
    expected = (table_rows(fields.HEADER, 0) + table_rows(fields.IMAGE, header)
                + table_rows(fields.CONTROL, header) + table_rows(fields.SEQUENCER, header)
                + table_rows(fields.STATUS_REPLY, header))
    assert doc_rows() == expected
