"""Row assembly: the pixels of image records, which may split a row anywhere, handed on as whole
rows only (``sync``).

An image record carries consecutive pixels of a frame from any pixel offset, so a row may begin in
one record and end in the next (records sized to the path's MTU cut rows anywhere). The store
takes rows whole, so a row goes on only when all of it has come, in order: its pieces in
consecutive records of one frame. A record that does not continue where the previous one ended
(a record lost or reordered, or another frame) abandons the row that was waiting for it, and its
own pixels up to the next row start are dropped; both are counted as incomplete rows.

Two row buffers: the pieces are written into the buffer of their row's parity as they come; a
row is *announced* to the reader as soon as its end is known to come (the record being written
reaches it), so a row inside one record passes through at once, and a split row from the moment
its last piece's record starts. The reader hands an announced row on from its first column,
never passing the bytes written so far. Each side moves a pixel per cycle; the reader lags the
writer by less than a row, so the writer never waits in a steady stream.
"""

from amaranth import Array, Cat, Module, Signal
from amaranth.lib import data, stream, wiring
from amaranth.lib.memory import Memory
from amaranth.lib.wiring import In, Out
from amaranth.utils import ceil_log2, exact_log2

from spec import records

from ..queue import Queue
from ..wire import layout
from .layouts import TAG, copy_tag, piece_layout, pixel_layout, tag_fields

__all__ = ["RowAssembler"]


def _newer(frame, than):
    """Serial-number order (RFC 1982) of 16-bit frame ids: ``frame`` is newer than ``than``."""
    diff = (frame - than)[:16]
    return (diff != 0) & ~diff[15]


class RowAssembler(wiring.Component):
    """Pixels of image records -> whole rows, in order.

    Parameters
    ----------
    dmd : :class:`spec.facts.DmdType`
    frame_bits : int
        Width of the frame tag on ``pixels`` (the low bits of the frame id).

    Members
    -------
    pieces : In(stream.Signature(piece_layout(dmd)))
        Each pixel of each valid image record, with its frame id, its position in the frame,
        where its record ends, and whether it is the record's first.
    pixels : Out(stream.Signature(pixel_layout(dmd, 1, frame_bits)))
        Whole rows, one pixel per transfer, left to right.
    counters : Out(layout(records.ROW_COUNTERS))
        Rows and pixel bytes handed on, rows abandoned incomplete, the last row's frame and row,
        and the newest frame id handed on (serial-number order).
    """

    def __init__(self, dmd, *, frame_bits=4):
        self._dmd = dmd
        self._frame_bits = frame_bits
        super().__init__({
            "pieces": In(stream.Signature(piece_layout(dmd))),
            "pixels": Out(stream.Signature(pixel_layout(dmd, 1, frame_bits))),
            "counters": Out(layout(records.ROW_COUNTERS)),
        })

    def elaborate(self, platform):
        m = Module()
        columns = self._dmd.columns
        column_bits = exact_log2(columns)
        announced_layout = data.StructLayout({"buffer": 1, "row": ceil_log2(self._dmd.rows),
                                              **tag_fields(self._dmd, 16)})
        m.submodules.memory = memory = Memory(shape=8, depth=2 * columns, init=[])
        write, read = memory.write_port(), memory.read_port()
        m.submodules.announced = announced = Queue(announced_layout, depth=2)

        busy = Signal(2)      # a buffer's row is announced and not yet all read
        fill = Array(Signal(range(columns + 1), name=f"fill{b}") for b in range(2))
        announcing, written = self._write(m, write, announced, busy, fill, column_bits)
        finishing, reading = self._read(m, read, announced, fill, columns)
        for b in range(2):
            with m.If(announcing & (written == b)):
                m.d.sync += busy[b].eq(1)
            with m.Elif(finishing & (reading == b)):
                m.d.sync += busy[b].eq(0)
        return m

    def _write(self, m, write, announced, busy, fill, column_bits):
        """The pieces into the buffers; returns (a row announced this cycle, its buffer)."""
        beat = self.pieces.payload
        column, row = beat.position[:column_bits], beat.position[column_bits:]
        buffer = row[0]
        tag = Signal(data.StructLayout(tag_fields(self._dmd, 16)))    # the frame being written
        following = Signal.like(beat.position)        # the position that continues the row
        valid = Signal()                              # the row being written began at column 0
        same_frame = Cat(beat[name] for name in TAG) == tag.as_value()
        continuing = valid & same_frame & (beat.position == following)
        starts = column == 0
        keep = starts | continuing
        # the row's end comes in this record: it goes on (at a row start, or at the first
        # pixel of the record that continues it)
        announce = keep & (starts | beat.first) & (((row + 1) << column_bits) <= beat.until)
        stall = (starts & busy.bit_select(buffer, 1)) | (announce & ~announced.w_stream.ready)
        taken = self.pieces.valid & ~stall
        m.d.comb += [
            self.pieces.ready.eq(~stall),
            write.addr.eq(Cat(column, buffer)),
            write.data.eq(beat.data),
            write.en.eq(taken & keep),
            announced.w_stream.valid.eq(taken & announce),
            announced.w_stream.payload.buffer.eq(buffer),
            announced.w_stream.payload.row.eq(row),
            *copy_tag(announced.w_stream.payload, beat),
        ]
        with m.If(taken):
            m.d.sync += [*copy_tag(tag, beat), following.eq(beat.position + 1), valid.eq(keep)]
            with m.If(keep):
                m.d.sync += fill[buffer].eq(column + 1)
            with m.If(beat.first & ~continuing):
                # a row left waiting for this record, and this record's pixels before its first row
                held = valid & (following[:column_bits] != 0)
                incomplete = self.counters.rows_incomplete
                m.d.sync += incomplete.eq(incomplete + held + ~starts)
        return taken & announce, buffer

    def _read(self, m, read, announced, fill, columns):
        """Announced rows out of the buffers; returns (a row's last pixel read this cycle, its
        buffer)."""
        out, head = self.pixels, announced.r_stream
        active = Signal()
        buffer = Signal()
        row = Signal.like(head.payload.row)
        tag = Signal(data.StructLayout(tag_fields(self._dmd, 16)))
        column = Signal(range(columns))
        out_column, out_row, out_tag = Signal.like(column), Signal.like(row), Signal.like(tag)
        advance = ~out.valid | out.ready
        readable = active & (column < fill[buffer])
        issue = advance & readable
        finishing = issue & (column == columns - 1)
        m.d.comb += [
            read.addr.eq(Cat(column, buffer)),
            read.en.eq(issue),
            out.payload.pixels[0].eq(read.data),
            out.payload.column.eq(out_column),
            out.payload.row.eq(out_row),
            *copy_tag(out.payload, out_tag),
            head.ready.eq(~active | finishing),
        ]
        with m.If(advance):
            m.d.sync += out.valid.eq(readable)
        with m.If(issue):
            m.d.sync += [out_column.eq(column), out_row.eq(row), out_tag.eq(tag), column.eq(column + 1)]
        with m.If(finishing):
            m.d.sync += active.eq(0)
        with m.If(head.valid & head.ready):
            m.d.sync += [active.eq(1), buffer.eq(head.payload.buffer), row.eq(head.payload.row),
                         *copy_tag(tag, head.payload), column.eq(0)]
        self._count(m, out_tag.frame)
        return finishing, buffer

    def _count(self, m, out_frame):
        """What was handed on."""
        out, count = self.pixels, self.counters
        columns = self._dmd.columns
        seen = Signal()
        with m.If(out.valid & out.ready):
            m.d.sync += count.payload_bytes.eq(count.payload_bytes + 1)
            with m.If(out.payload.column == columns - 1):
                m.d.sync += [count.rows.eq(count.rows + 1), count.last_frame.eq(out_frame),
                             count.last_row.eq(out.payload.row), seen.eq(1)]
                with m.If(~seen | _newer(out_frame, count.newest_frame)):
                    m.d.sync += count.newest_frame.eq(out_frame)
