"""Status replies: a snapshot of every counter, sent back to whoever asked."""

from amaranth import Cat, Module, Signal
from amaranth.lib import stream, wiring
from amaranth.lib.wiring import In, Out

from spec import records, wire
from spec.records import RecordType

from ..net.layouts import BodyByte, Peer, ReplyKind, ReplyRequest
from ..wire import layout, to_bytes
from .parser import Query

__all__ = ["StatusReply", "REPLY_LENGTH"]

REPLY_LENGTH = wire.size(records.HEADER) + wire.size(records.STATUS_REPLY)


class StatusReply(wiring.Component):
    """Answers each status query with a status reply record.

    The counters are copied when the query is taken, so one reply is one consistent instant.

    Members
    -------
    queries : In(stream.Signature(Query))
    net : In(layout(records.NET_COUNTERS))
    app : In(layout(records.APP_COUNTERS))
    system : In(layout(records.SYSTEM_STATUS))
    request : Out(stream.Signature(ReplyRequest))
        A UDP reply to the asker, ``REPLY_LENGTH`` bytes.
    body : Out(stream.Signature(BodyByte))
        The reply record.
    """

    queries: In(stream.Signature(Query))
    net: In(layout(records.NET_COUNTERS))
    app: In(layout(records.APP_COUNTERS))
    system: In(layout(records.SYSTEM_STATUS))
    request: Out(stream.Signature(ReplyRequest))
    body: Out(stream.Signature(BodyByte))

    def elaborate(self, platform):
        m = Module()
        query = self.queries.payload
        values = {"magic": records.MAGIC, "version": records.VERSION, "type": RecordType.STATUS_REPLY,
                  "sequence": query.sequence}
        for source, table in ((self.net, records.NET_COUNTERS), (self.app, records.APP_COUNTERS),
                              (self.system, records.SYSTEM_STATUS)):
            values.update({name: source[name] for name, _ in table})
        record = Cat(*to_bytes(records.HEADER + records.STATUS_REPLY, values))
        snapshot = Signal(len(record))
        peer = Signal(Peer)
        index = Signal(range(REPLY_LENGTH))

        m.d.comb += [
            self.request.payload.kind.eq(ReplyKind.UDP),
            self.request.payload.peer.eq(peer),
            self.request.payload.length.eq(REPLY_LENGTH),
            self.body.payload.data.eq(snapshot.word_select(index, 8)),
            self.body.payload.last.eq(index == REPLY_LENGTH - 1),
        ]
        with m.FSM():
            with m.State("IDLE"):
                m.d.comb += self.queries.ready.eq(1)
                with m.If(self.queries.valid):
                    m.d.sync += [snapshot.eq(record), peer.eq(query.peer), index.eq(0)]
                    m.next = "REQUEST"
            with m.State("REQUEST"):
                m.d.comb += self.request.valid.eq(1)
                with m.If(self.request.ready):
                    m.next = "BODY"
            with m.State("BODY"):
                m.d.comb += self.body.valid.eq(1)
                with m.If(self.body.ready):
                    m.d.sync += index.eq(index + 1)
                    with m.If(self.body.payload.last):
                        m.next = "IDLE"
        return m
