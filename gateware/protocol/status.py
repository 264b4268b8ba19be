"""Status replies: a snapshot of every counter, sent back to whoever asked."""

from amaranth import Cat, Module, Signal
from amaranth.lib import stream, wiring
from amaranth.lib.wiring import In, Out

from spec import records, wire
from spec.records import RecordType

from ..net.layouts import BodyByte, Peer, ReplyKind, ReplyRequest
from ..wire import layout, to_bytes
from .parser import Query

__all__ = ["StatusReply", "PROJECTOR_PARTS"]

#: The projector's status reply: its parts, each a member of that name (:data:`records.STATUS_REPLY`).
PROJECTOR_PARTS = {"net": records.NET_COUNTERS, "app": records.APP_COUNTERS, "system": records.SYSTEM_STATUS}


class StatusReply(wiring.Component):
    """Answers each status query with a status reply record.

    The counters are copied when the query is taken, so one reply is one consistent instant.

    Parameters
    ----------
    kind : :class:`spec.records.RecordType`
        The reply's record type (the projector's ``STATUS_REPLY``, a sync master's ``MASTER_STATUS``).
    parts : dict
        ``{member name: table}``: the reply's body is the tables in this order.

    Members
    -------
    queries : In(stream.Signature(Query))
    <part> : In(layout(table))
        One per part (the projector's: ``net``, ``app``, ``system``).
    request : Out(stream.Signature(ReplyRequest))
        A UDP reply to the asker, as long as the record.
    body : Out(stream.Signature(BodyByte))
        The reply record.
    """

    def __init__(self, kind=RecordType.STATUS_REPLY, parts=PROJECTOR_PARTS):
        self._kind, self._parts = kind, parts
        self.length = wire.size(records.HEADER) + sum(wire.size(table) for table in parts.values())
        super().__init__({
            "queries": In(stream.Signature(Query)),
            **{name: In(layout(table)) for name, table in parts.items()},
            "request": Out(stream.Signature(ReplyRequest)),
            "body": Out(stream.Signature(BodyByte)),
        })

    def elaborate(self, platform):
        m = Module()
        query = self.queries.payload
        values = {"magic": records.MAGIC, "version": records.VERSION, "type": self._kind,
                  "sequence": query.sequence}
        for part, table in self._parts.items():
            values.update({name: getattr(self, part)[name] for name, _ in table})
        body = [entry for table in self._parts.values() for entry in table]
        record = Cat(*to_bytes(records.HEADER + body, values))
        length = self.length
        snapshot = Signal(len(record))
        peer = Signal(Peer)
        index = Signal(range(length))

        m.d.comb += [
            self.request.payload.kind.eq(ReplyKind.UDP),
            self.request.payload.peer.eq(peer),
            self.request.payload.length.eq(length),
            self.body.payload.data.eq(snapshot.word_select(index, 8)),
            self.body.payload.last.eq(index == length - 1),
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
