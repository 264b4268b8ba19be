"""The application protocol's receive side: checks each record, then applies it.

One UDP datagram carries one record (see ``docs/protocol.md``). The parser collects the common
header and the type's own header, checks them all against each other, against the datagram's
length and against the DMD geometry, and only then acts: an image or delta record's pixels go
to the row assembler (:class:`~gateware.protocol.rows.RowAssembler`) as pixels with their position in
the frame, a control record updates :attr:`Parser.settings`, a sequencer record's register set
leaves whole on :attr:`Parser.registers`, a sequence entry record on :attr:`Parser.entries`, a
status query asks
:class:`~gateware.protocol.status.StatusReply` for an answer. A record that fails a check is
consumed and counted under its cause and has no other effect.
"""

from types import SimpleNamespace

from amaranth import Cat, Module, Mux, Signal
from amaranth.lib import data, stream, wiring
from amaranth.lib.wiring import In, Out

from spec import records, wire
from spec.records import RecordType

from ..net.layouts import OFFSET_BITS, Datagram, Peer
from ..registers import Registers, wire_registers
from ..wire import byte_slice, layout
from .layouts import piece_layout

__all__ = ["Parser", "Query", "capture", "follow_sequence", "config_init", "CONFIG_LAYOUT", "ENTRY_LAYOUT"]

CONFIG_LAYOUT = layout(records.CONFIG)
#: A sequence entry record's fields, as the store's entry table takes them.
ENTRY_LAYOUT = layout(records.ENTRY)
_HEADER = wire.size(records.HEADER)
_IMAGE_END = _HEADER + wire.size(records.IMAGE)
_DELTA_END = _HEADER + wire.size(records.DELTA)
_CONTROL_END = _HEADER + wire.size(records.CONTROL)
_SEQUENCER_END = _HEADER + wire.size(records.SEQUENCER)
_ENTRY_END = _HEADER + wire.size(records.ENTRY)
_CAPTURED = max(_IMAGE_END, _DELTA_END, _CONTROL_END, _SEQUENCER_END, _ENTRY_END)
_SEQUENCE_BITS = dict(records.HEADER)["sequence"]


class Query(data.Struct):
    """A status query: who asked, and the sequence number the answer echoes."""
    peer: Peer
    sequence: _SEQUENCE_BITS


def capture(m, datagrams, index, captured, peer, length):
    """Keep a record's first bytes: byte ``i`` of each datagram taken from ``datagrams`` into
    byte ``i`` of ``captured`` (as many as it holds; ``index`` counts them, the caller zeroes
    it between records), its sender into ``peer`` and its length into ``length``. A record
    shorter than ``captured`` reads as zeros past its end, not as the record before it."""
    size = len(captured) // 8
    beat = datagrams.payload
    with m.If(datagrams.valid & datagrams.ready):
        m.d.sync += index.eq(index + 1)
        with m.If(index == 0):
            m.d.sync += [captured.eq(beat.data << 8 * (size - 1)), peer.eq(beat.peer), length.eq(beat.length)]
        for i in range(1, size):
            with m.If(index == i):
                m.d.sync += byte_slice(captured, size, i, 1).eq(beat.data)


def follow_sequence(m, sequence, gaps):
    """Count in ``gaps`` a valid record whose ``sequence`` number is not the last one's + 1
    (from the second record on). Called where a record is known valid."""
    seen, last = Signal(), Signal.like(sequence)
    with m.If(seen & (sequence != (last + 1)[:len(last)])):
        m.d.sync += gaps.eq(gaps + 1)
    m.d.sync += [seen.eq(1), last.eq(sequence)]


def config_init(*, mac, ip, port, bit_depth=8, armed=False):
    """The configuration the gateware starts with (build parameters)."""
    return {"bit_depth": bit_depth, "armed": int(armed), "sequence_length": 1, "entries": 0, "loop": 1,
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

    Members
    -------
    datagrams : In(stream.Signature(Datagram))
        Committed UDP payloads from :class:`gateware.net.stack.Stack`.
    pieces : Out(stream.Signature(piece_layout(dmd)))
        The pixels of valid image and delta records, one per transfer, in order, each with its frame id
        and position in the frame, where its record ends and whether it is the record's first.
    settings : Out(layout(records.CONFIG))
        The configuration registers; control records update the fields they select.
    registers : Out(stream.Signature(Registers))
        The register set of each valid sequencer record, one transfer per record (the parser
        waits for it to be taken).
    trigger : Out(1)
        One-cycle pulse for a control record with the software-trigger action.
    entries : Out(stream.Signature(ENTRY_LAYOUT))
        Each valid sequence entry record, one transfer per record (the parser waits for it).
    sequence_start : Out(1)
        One-cycle pulse for a control record with the sequence-start action (after its fields
        are applied).
    queries : Out(stream.Signature(Query))
        Valid status queries, for the status reply.
    counters : Out(layout(records.RECORD_COUNTERS))
        Records accepted per type (image and delta records together), dropped per cause,
        sequence gaps.
    """

    def __init__(self, dmd, config, *, beats=1):
        self._dmd, self._beats = dmd, beats
        super().__init__({
            "datagrams": In(stream.Signature(Datagram)),
            "pieces": Out(stream.Signature(piece_layout(dmd))),
            "settings": Out(CONFIG_LAYOUT, init=config),
            "trigger": Out(1),
            "registers": Out(stream.Signature(Registers)),
            "entries": Out(stream.Signature(ENTRY_LAYOUT)),
            "sequence_start": Out(1),
            "queries": Out(stream.Signature(Query)),
            "counters": Out(layout(records.RECORD_COUNTERS)),
        })

    #: Why a record is dropped, in the order the checks are made (``drop_app_<cause>``).
    _CAUSES = ["magic", "version", "type", "empty", "length", "rows", "value"]

    def _cause(self, m, header, pixels, delta, control, sequencer, entry, length, needed, reload_terms):
        """The first check the record in ``captured`` fails: 1 + its index in :attr:`_CAUSES`,
        or 0 when it passes every one. ``pixels``: where an image or delta record's pixels go;
        ``reload_terms``: the sequencer record's :func:`spec.records.group_reload`, registered."""
        dmd = self._dmd
        is_image = (header.type == RecordType.IMAGE) | (header.type == RecordType.DELTA)
        cause = Signal(range(8))
        causes = self._CAUSES
        names = [name for name, _ in records.CONFIG]

        def applies(name):
            return control.apply[names.index(name)]
        frames = records.sequence_frames(dmd.rows, dmd.columns)    # a longer sequence: a bad value
        with m.If(header.magic != records.MAGIC):
            m.d.comb += cause.eq(1 + causes.index("magic"))
        with m.Elif(header.version != records.VERSION):
            m.d.comb += cause.eq(1 + causes.index("version"))
        with m.Elif(Cat(header.type == kind for kind in (RecordType.IMAGE, RecordType.CONTROL,
                                                         RecordType.STATUS_QUERY, RecordType.SEQUENCER,
                                                         RecordType.ENTRY, RecordType.DELTA)).any() == 0):
            m.d.comb += cause.eq(1 + causes.index("type"))
        with m.Elif(length < needed):
            m.d.comb += cause.eq(1 + causes.index("length"))
        with m.Elif(is_image & (length == needed)):
            m.d.comb += cause.eq(1 + causes.index("empty"))
        with m.Elif(~is_image & (length != needed)):
            m.d.comb += cause.eq(1 + causes.index("length"))
        with m.Elif(is_image & (pixels.until > dmd.rows * dmd.columns)):
            m.d.comb += cause.eq(1 + causes.index("rows"))
        with m.Elif((header.type == RecordType.DELTA) & Cat(records.delta_faults(delta).values()).any()):
            m.d.comb += cause.eq(1 + causes.index("value"))
        with m.Elif((header.type == RecordType.CONTROL)
                    & Cat(records.config_faults(control, applies, frames).values()).any()):
            m.d.comb += cause.eq(1 + causes.index("value"))
        with m.Elif((header.type == RecordType.ENTRY)
                    & Cat(records.entry_faults(entry, self.settings.sequence_length).values()).any()):
            m.d.comb += cause.eq(1 + causes.index("value"))
        with m.Elif((header.type == RecordType.SEQUENCER)
                    & Cat(records.register_faults(sequencer, dmd, self._beats,
                                                    reload_terms=reload_terms).values()).any()):
            m.d.comb += cause.eq(1 + causes.index("value"))
        return cause

    def _reload_terms(self, m, sequencer):
        """A sequencer record's group reload (:func:`spec.records.group_reload`: a product of two
        of its fields), registered while the record waits a cycle (WEIGH), so that the checks
        start from registers."""
        terms = records.group_reload(sequencer, self._dmd, self._beats)
        registered = [Signal(term.shape(), name=name) for term, name in
                      zip(terms, ("group_clears", "group_reload"), strict=True)]
        m.d.sync += [r.eq(term) for r, term in zip(registered, terms, strict=True)]
        return registered

    def _needed(self, m, header):
        """The bytes of header a record of ``header.type`` needs before it can be checked: the
        whole record, but for an image record's pixels."""
        needed = Signal(range(_CAPTURED + 1))
        with m.Switch(header.type):
            with m.Case(RecordType.IMAGE):
                m.d.comb += needed.eq(_IMAGE_END)
            with m.Case(RecordType.DELTA):
                m.d.comb += needed.eq(_DELTA_END)
            with m.Case(RecordType.CONTROL):
                m.d.comb += needed.eq(_CONTROL_END)
            with m.Case(RecordType.SEQUENCER):
                m.d.comb += needed.eq(_SEQUENCER_END)
            with m.Case(RecordType.ENTRY):
                m.d.comb += needed.eq(_ENTRY_END)
            with m.Default():
                m.d.comb += needed.eq(_HEADER)
        return needed

    def _pixels(self, m, header, image, delta, length, needed):
        """Where an image or delta record's pixels go: ``offset``, ``until`` (one past the last),
        and the delta's ``base`` and ``carried`` (both 0 for a whole frame's image record; a
        row count beyond the frame is kept as rows + 1, for the store to refuse)."""
        piece = self.pieces.payload
        # (``until`` as wide as the sum: the frame check must not see it wrap)
        out = SimpleNamespace(offset=Signal.like(image.offset), until=Signal(len(image.offset) + 1),
                              base=Signal.like(piece.base), carried=Signal.like(piece.carried))
        rows = self._dmd.rows
        with m.If(header.type == RecordType.DELTA):
            m.d.comb += [out.offset.eq(delta.offset), out.base.eq(delta.base),
                         out.carried.eq(Mux(delta.carried > rows, rows + 1, delta.carried))]
        with m.Else():
            m.d.comb += out.offset.eq(image.offset)
        m.d.comb += out.until.eq(out.offset + (length - needed))
        return out

    def elaborate(self, platform):
        m = Module()
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
        delta = part(records.DELTA, _HEADER)
        control = part(records.CONTROL, _HEADER)
        sequencer = part(records.SEQUENCER, _HEADER)
        entry = part(records.ENTRY, _HEADER)
        m.d.comb += [self.registers.payload.eq(wire_registers(sequencer)), self.entries.payload.eq(entry)]
        peer = Signal(Peer)
        length = Signal(OFFSET_BITS)

        capture(m, self.datagrams, index, captured, peer, length)

        needed = self._needed(m, header)
        pixels = self._pixels(m, header, image, delta, length, needed)
        reload_terms = self._reload_terms(m, sequencer)
        cause = self._cause(m, header, pixels, delta, control, sequencer, entry, length, needed, reload_terms)
        causes = self._CAUSES

        position = Signal.like(self.pieces.payload.position)
        first = Signal()

        def bump(name, by=1):
            m.d.sync += counters[name].eq(counters[name] + by)

        m.d.sync += [self.trigger.eq(0), self.sequence_start.eq(0)]
        with m.FSM():
            with m.State("HEAD"):
                m.d.comb += self.datagrams.ready.eq(1)
                with m.If(taken):
                    m.d.sync += ended.eq(beat.last)
                    with m.If(beat.last | ((index >= _HEADER - 1) & (index + 1 == needed))):
                        m.next = "WEIGH"
            with m.State("WEIGH"):
                # the record whole in ``captured``: its group reload registered (reload_terms)
                m.next = "CHECK"
            with m.State("CHECK"):
                with m.If(cause != 0):
                    for i, name in enumerate(causes):
                        with m.If(cause == 1 + i):
                            bump(f"drop_app_{name}")
                    m.next = "DISCARD"
                with m.Else():
                    follow_sequence(m, header.sequence, counters.sequence_gaps)
                    with m.Switch(header.type):
                        with m.Case(RecordType.IMAGE, RecordType.DELTA):
                            m.d.sync += [position.eq(pixels.offset), first.eq(1)]
                            m.next = "PIXELS"
                        with m.Case(RecordType.CONTROL):
                            bump("records_control")
                            for i, (name, _) in enumerate(records.CONFIG):
                                with m.If(control.apply[i]):
                                    m.d.sync += self.settings[name].eq(control[name])
                            m.d.sync += [
                                self.trigger.eq((control.action & records.Action.SOFTWARE_TRIGGER) != 0),
                                self.sequence_start.eq((control.action & records.Action.SEQUENCE_START) != 0)]
                            m.next = "DISCARD"
                        with m.Case(RecordType.SEQUENCER):
                            bump("records_sequencer")
                            m.next = "REGISTERS"
                        with m.Case(RecordType.ENTRY):
                            bump("records_entry")
                            m.next = "ENTRY"
                        with m.Default():
                            bump("records_status")
                            m.next = "QUERY"
            with m.State("PIXELS"):
                m.d.comb += [
                    self.pieces.valid.eq(self.datagrams.valid),
                    self.pieces.payload.data.eq(beat.data),
                    self.pieces.payload.frame.eq(image.frame),
                    self.pieces.payload.base.eq(pixels.base),
                    self.pieces.payload.carried.eq(pixels.carried),
                    self.pieces.payload.position.eq(position),
                    self.pieces.payload.until.eq(pixels.until),
                    self.pieces.payload.first.eq(first),
                    self.datagrams.ready.eq(self.pieces.ready),
                ]
                with m.If(taken):
                    m.d.sync += [position.eq(position + 1), first.eq(0)]
                    with m.If(beat.last):
                        bump("records_image")
                        m.d.sync += [index.eq(0), ended.eq(0)]
                        m.next = "HEAD"
            with m.State("REGISTERS"):
                m.d.comb += self.registers.valid.eq(1)
                with m.If(self.registers.ready):
                    m.next = "DISCARD"
            with m.State("ENTRY"):
                m.d.comb += self.entries.valid.eq(1)
                with m.If(self.entries.ready):
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
