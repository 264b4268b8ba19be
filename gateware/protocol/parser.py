"""The application protocol's receive side: checks each record, then applies it.

One UDP datagram carries one record (see ``docs/protocol.md``). The parser collects the common
header and the type's own header, checks them all against each other, against the datagram's
length and against the DMD geometry, and only then acts: an image record's rows go to the
bit-plane serialiser, a control record updates :attr:`Parser.settings`, a sequencer record's
register set leaves whole on :attr:`Parser.registers`, a status query asks
:class:`~gateware.protocol.status.StatusReply` for an answer. A record that fails a check is
consumed and counted under its cause and has no other effect.
"""

from amaranth import Cat, Module, Signal
from amaranth.lib import data, stream, wiring
from amaranth.lib.wiring import In, Out
from amaranth.utils import ceil_log2, exact_log2

from spec import records, wire
from spec.records import RecordType
from spec.schedule import row_cycles

from ..net.layouts import OFFSET_BITS, Datagram, Peer
from ..registers import Registers, wire_registers
from ..wire import byte_slice, layout
from .layouts import pixel_layout

__all__ = ["Parser", "Query", "config_init", "CONFIG_LAYOUT"]

CONFIG_LAYOUT = layout(records.CONFIG)
_HEADER = wire.size(records.HEADER)
_IMAGE_END = _HEADER + wire.size(records.IMAGE)
_CONTROL_END = _HEADER + wire.size(records.CONTROL)
_SEQUENCER_END = _HEADER + wire.size(records.SEQUENCER)
_CAPTURED = max(_IMAGE_END, _CONTROL_END, _SEQUENCER_END)


class Query(data.Struct):
    """A status query: who asked, and the sequence number the answer echoes."""
    peer: Peer
    sequence: 32


def config_init(*, mac, ip, port, bit_depth=8, armed=False):
    """The configuration the gateware starts with (build parameters)."""
    return {"bit_depth": bit_depth, "armed": int(armed), "sequence_length": 1,
            "mac": mac, "ip": ip, "port": port}


class Parser(wiring.Component):
    """Checks records and hands them on.

    Parameters
    ----------
    dmd : :class:`spec.facts.DmdType`
        Rows and columns that image records must fit.
    beats : int
        DCLK beats per ``dmd`` cycle the sequencer is built for (its shortest ``row_period``).
    config : dict
        Initial configuration (:func:`config_init`).
    frame_bits : int
        Bits of the frame id passed to the serialiser as its frame tag (the store's slot).

    Members
    -------
    datagrams : In(stream.Signature(Datagram))
        Committed UDP payloads from :class:`gateware.net.stack.Stack`.
    pixels : Out(stream.Signature(pixel_layout(dmd, 1, frame_bits)))
        The rows of valid image records, one 8-bit pixel per transfer, left to right.
    settings : Out(layout(records.CONFIG))
        The configuration registers; control records update the fields they select.
    registers : Out(stream.Signature(Registers))
        The register set of each valid sequencer record, one transfer per record (the parser
        waits for it to be taken).
    trigger : Out(1)
        One-cycle pulse for a control record with the software-trigger action.
    queries : Out(stream.Signature(Query))
        Valid status queries, for the status reply.
    counters : Out(layout(records.APP_COUNTERS))
        Records accepted per type, dropped per cause, sequence gaps, rows and bytes handed on.
    """

    def __init__(self, dmd, config, *, frame_bits=4, beats=1):
        self._dmd, self._beats = dmd, beats
        self._frame_bits = frame_bits
        super().__init__({
            "datagrams": In(stream.Signature(Datagram)),
            "pixels": Out(stream.Signature(pixel_layout(dmd, 1, frame_bits))),
            "settings": Out(CONFIG_LAYOUT, init=config),
            "trigger": Out(1),
            "registers": Out(stream.Signature(Registers)),
            "queries": Out(stream.Signature(Query)),
            "counters": Out(layout(records.APP_COUNTERS)),
        })

    def elaborate(self, platform):
        m = Module()
        dmd = self._dmd
        counters = self.counters
        beat = self.datagrams.payload
        taken = self.datagrams.valid & self.datagrams.ready

        index = Signal(OFFSET_BITS)
        ended = Signal()
        captured = Signal(8 * _CAPTURED)

        def part(table, first):
            return data.View(layout(table),
                             byte_slice(captured, _CAPTURED, first, wire.size(table)))
        header = part(records.HEADER, 0)
        image = part(records.IMAGE, _HEADER)
        control = part(records.CONTROL, _HEADER)
        sequencer = part(records.SEQUENCER, _HEADER)
        m.d.comb += self.registers.payload.eq(wire_registers(sequencer))
        peer = Signal(Peer)
        length = Signal(OFFSET_BITS)

        with m.If(taken):
            m.d.sync += index.eq(index + 1)
            with m.If(index == 0):
                # a record shorter than its header reads as zeros there, not as the last one
                m.d.sync += captured.eq(beat.data << 8 * (_CAPTURED - 1))
            for i in range(1, _CAPTURED):
                with m.If(index == i):
                    m.d.sync += byte_slice(captured, _CAPTURED, i, 1).eq(beat.data)
            with m.If(index == 0):
                m.d.sync += [peer.eq(beat.peer), length.eq(beat.length)]

        # The header each record type needs before it can be checked, and its whole length.
        needed = Signal(range(_CAPTURED + 1))
        expected = Signal(OFFSET_BITS + 17)
        with m.Switch(header.type):
            with m.Case(RecordType.IMAGE):
                m.d.comb += [needed.eq(_IMAGE_END),
                             expected.eq(_IMAGE_END + (image.row_count << exact_log2(dmd.columns)))]
            with m.Case(RecordType.CONTROL):
                m.d.comb += [needed.eq(_CONTROL_END), expected.eq(_CONTROL_END)]
            with m.Case(RecordType.SEQUENCER):
                m.d.comb += [needed.eq(_SEQUENCER_END), expected.eq(_SEQUENCER_END)]
            with m.Default():
                m.d.comb += [needed.eq(_HEADER), expected.eq(_HEADER)]

        cause = Signal(range(8))
        causes = ["magic", "version", "type", "empty", "length", "rows", "value"]
        names = [name for name, _ in records.CONFIG]

        def applies(name):
            return control.apply[names.index(name)]
        with m.If(header.magic != records.MAGIC):
            m.d.comb += cause.eq(1 + causes.index("magic"))
        with m.Elif(header.version != records.VERSION):
            m.d.comb += cause.eq(1 + causes.index("version"))
        with m.Elif((header.type != RecordType.IMAGE) & (header.type != RecordType.CONTROL)
                    & (header.type != RecordType.STATUS_QUERY) & (header.type != RecordType.SEQUENCER)):
            m.d.comb += cause.eq(1 + causes.index("type"))
        with m.Elif(header.length == 0):
            m.d.comb += cause.eq(1 + causes.index("empty"))
        with m.Elif((header.length != length) | (length < needed)):
            m.d.comb += cause.eq(1 + causes.index("length"))
        with m.Elif((header.type == RecordType.IMAGE) & (image.row_count == 0)):
            m.d.comb += cause.eq(1 + causes.index("empty"))
        with m.Elif(header.length != expected):
            m.d.comb += cause.eq(1 + causes.index("length"))
        with m.Elif((header.type == RecordType.IMAGE)
                    & ((image.first_row + image.row_count > dmd.rows) | (image.row_bytes != dmd.columns))):
            m.d.comb += cause.eq(1 + causes.index("rows"))
        with m.Elif((header.type == RecordType.CONTROL)
                    & ((applies("bit_depth") & ((control.bit_depth == 0) | (control.bit_depth > 8)))
                       | (applies("armed") & (control.armed > 1))
                       | (applies("sequence_length") & (control.sequence_length == 0)))):
            m.d.comb += cause.eq(1 + causes.index("value"))
        with m.Elif((header.type == RecordType.SEQUENCER)
                    & Cat(records.register_faults(sequencer, row_cycles(dmd, self._beats)).values()).any()):
            m.d.comb += cause.eq(1 + causes.index("value"))

        sequence_seen = Signal()
        sequence_last = Signal(32)
        column = Signal(ceil_log2(dmd.columns))
        row = Signal(16)

        def bump(name, by=1):
            m.d.sync += counters[name].eq(counters[name] + by)

        m.d.sync += self.trigger.eq(0)
        with m.FSM():
            with m.State("HEAD"):
                m.d.comb += self.datagrams.ready.eq(1)
                with m.If(taken):
                    m.d.sync += ended.eq(beat.last)
                    with m.If(beat.last | ((index >= _HEADER - 1) & (index + 1 == needed))):
                        m.next = "CHECK"
            with m.State("CHECK"):
                with m.If(cause != 0):
                    for i, name in enumerate(causes):
                        with m.If(cause == 1 + i):
                            bump(f"drop_app_{name}")
                    m.next = "DISCARD"
                with m.Else():
                    with m.If(sequence_seen & (header.sequence != (sequence_last + 1)[:32])):
                        bump("sequence_gaps")
                    m.d.sync += [sequence_seen.eq(1), sequence_last.eq(header.sequence)]
                    with m.Switch(header.type):
                        with m.Case(RecordType.IMAGE):
                            m.d.sync += [column.eq(0), row.eq(image.first_row)]
                            m.next = "PIXELS"
                        with m.Case(RecordType.CONTROL):
                            bump("records_control")
                            for i, (name, _) in enumerate(records.CONFIG):
                                with m.If(control.apply[i]):
                                    m.d.sync += self.settings[name].eq(control[name])
                            m.d.sync += self.trigger.eq(
                                (control.action & records.Action.SOFTWARE_TRIGGER) != 0)
                            m.next = "DISCARD"
                        with m.Case(RecordType.SEQUENCER):
                            bump("records_sequencer")
                            m.next = "REGISTERS"
                        with m.Default():
                            bump("records_status")
                            m.next = "QUERY"
            with m.State("PIXELS"):
                m.d.comb += [
                    self.pixels.valid.eq(self.datagrams.valid),
                    self.pixels.payload.pixels[0].eq(beat.data),
                    self.pixels.payload.column.eq(column),
                    self.pixels.payload.row.eq(row),
                    self.pixels.payload.frame.eq(image.frame),
                    self.datagrams.ready.eq(self.pixels.ready),
                ]
                with m.If(taken):
                    bump("payload_bytes")
                    m.d.sync += column.eq(column + 1)
                    with m.If(column == dmd.columns - 1):
                        bump("rows")
                        m.d.sync += [row.eq(row + 1), counters.last_row.eq(row),
                                     counters.last_frame.eq(image.frame)]
                    with m.If(beat.last):
                        bump("records_image")
                        m.d.sync += [index.eq(0), ended.eq(0)]
                        m.next = "HEAD"
            with m.State("REGISTERS"):
                m.d.comb += self.registers.valid.eq(1)
                with m.If(self.registers.ready):
                    m.next = "DISCARD"
            with m.State("QUERY"):
                m.d.comb += [
                    self.queries.valid.eq(1),
                    self.queries.payload.peer.eq(peer),
                    self.queries.payload.sequence.eq(header.sequence),
                ]
                with m.If(self.queries.ready):
                    m.d.sync += [index.eq(0), ended.eq(0)]
                    m.next = "HEAD"
            with m.State("DISCARD"):
                # The rest of a dropped record (or nothing, if it has ended).
                m.d.comb += self.datagrams.ready.eq(~ended)
                with m.If(ended | (taken & beat.last)):
                    m.d.sync += [index.eq(0), ended.eq(0)]
                    m.next = "HEAD"
        return m
