"""A sync master's network endpoint: its settings and software trigger from master control
records, its pulses and refusals in master status replies.

The sync master of a tiled display (:class:`~gateware.sync.master.SyncMaster`) speaks the
projector's protocol (``docs/protocol.md``) with two record types of its own: a master control
record sets its configuration (:data:`spec.records.MASTER_CONFIG`) and may fire a software
trigger; a status query is answered with a master status reply. Every other record is dropped
and counted, as the projector's parser drops what it cannot obey.
"""

from amaranth import Cat, Module, Mux, Signal
from amaranth.lib import data, stream, wiring
from amaranth.lib.wiring import In, Out, connect

from spec import records, wire
from spec.records import RecordType

from ..mac.layouts import ByteBeat
from ..net.layouts import OFFSET_BITS, Datagram, Peer
from ..net.stack import Stack
from ..wire import byte_slice, layout
from .parser import Query, capture, follow_sequence
from .status import StatusReply

__all__ = ["MasterParser", "MasterEndpoint", "MASTER_CONFIG_LAYOUT", "master_config_init"]

#: The configuration a sync master obeys (fields: :data:`records.MASTER_CONFIG`).
MASTER_CONFIG_LAYOUT = layout(records.MASTER_CONFIG)
_HEADER = wire.size(records.HEADER)
_CONTROL_END = _HEADER + wire.size(records.MASTER_CONTROL)
#: The master status reply's parts (the status reply's members of these names).
_REPLY_PARTS = {"net": records.NET_COUNTERS, "records": records.MASTER_RECORD_COUNTERS,
                "master": records.MASTER_STATUS}


def master_config_init(*, mode, armed, period, min_period, width):
    """The configuration a sync master starts with (build parameters; times in its cycles)."""
    return {"mode": getattr(mode, "value", mode), "armed": int(armed), "period": period, "min_period": min_period,
            "width": width}


class MasterParser(wiring.Component):
    """Checks the records sent to a sync master and obeys the valid ones.

    Checks, in order, the first failure dropping the record and counting it (``drop_app_*``):
    magic, version, type (a master control record or a status query), length (exactly the
    type's), and for a master control record the configuration it would leave in force
    (:func:`spec.records.master_config_faults`). A dropped record changes nothing.

    Parameters
    ----------
    config : dict
        The configuration at reset (:func:`master_config_init`).

    Members
    -------
    datagrams : In(stream.Signature(Datagram))
        Committed UDP payloads from :class:`gateware.net.stack.Stack`.
    settings : Out(MASTER_CONFIG_LAYOUT)
        The configuration: each field a valid master control record applies takes its value.
    trigger : Out(1)
        One-cycle pulse for a master control record with the software trigger action (the cycle
        after its fields are applied).
    queries : Out(stream.Signature(Query))
        Valid status queries, for the status reply.
    counters : Out(layout(records.MASTER_RECORD_COUNTERS))
        Records obeyed per type, dropped per cause, sequence gaps.
    """

    #: Why a record is dropped, in the order the checks are made (``drop_app_<cause>``).
    CAUSES = ("magic", "version", "type", "length", "value")

    def __init__(self, config):
        super().__init__({
            "datagrams": In(stream.Signature(Datagram)),
            "settings": Out(MASTER_CONFIG_LAYOUT, init=config),
            "trigger": Out(1),
            "queries": Out(stream.Signature(Query)),
            "counters": Out(layout(records.MASTER_RECORD_COUNTERS)),
        })

    def _cause(self, m, header, control, length):
        """The first check the captured record fails, as 1 + its index in :attr:`CAUSES`; 0 if none."""
        is_control = header.type == RecordType.MASTER_CONTROL
        names = [name for name, _ in records.MASTER_CONFIG]
        merged = {name: Mux(control.apply[i], control[name], self.settings[name]) for i, name in enumerate(names)}
        checks = [
            header.magic != records.MAGIC,
            header.version != records.VERSION,
            ~is_control & (header.type != RecordType.STATUS_QUERY),
            length != Mux(is_control, _CONTROL_END, _HEADER),
            is_control & Cat(records.master_config_faults(merged).values()).any(),
        ]
        cause = Signal(range(len(checks) + 1))
        for i, failed in reversed(list(enumerate(checks))):     # the first one that fails wins
            with m.If(failed):
                m.d.comb += cause.eq(1 + i)
        return cause

    def elaborate(self, platform):
        m = Module()
        counters = self.counters
        beat = self.datagrams.payload
        index = Signal(OFFSET_BITS)
        captured = Signal(8 * _CONTROL_END)
        peer = Signal(Peer)
        length = Signal(OFFSET_BITS)
        capture(m, self.datagrams, index, captured, peer, length)
        header = data.View(layout(records.HEADER), byte_slice(captured, _CONTROL_END, 0, _HEADER))
        control = data.View(layout(records.MASTER_CONTROL),
                            byte_slice(captured, _CONTROL_END, _HEADER, _CONTROL_END - _HEADER))
        cause = self._cause(m, header, control, length)

        def bump(name):
            m.d.sync += counters[name].eq(counters[name] + 1)

        m.d.sync += self.trigger.eq(0)
        m.d.comb += [self.queries.payload.peer.eq(peer), self.queries.payload.sequence.eq(header.sequence)]
        with m.FSM():
            with m.State("RECEIVE"):
                # the whole datagram, its first bytes kept (a longer one fails the length check)
                m.d.comb += self.datagrams.ready.eq(1)
                with m.If(self.datagrams.valid & beat.last):
                    m.next = "CHECK"
            with m.State("CHECK"):
                m.d.sync += index.eq(0)
                m.next = "RECEIVE"
                with m.If(cause != 0):
                    for i, name in enumerate(self.CAUSES):
                        with m.If(cause == 1 + i):
                            bump(f"drop_app_{name}")
                with m.Else():
                    follow_sequence(m, header.sequence, counters.sequence_gaps)
                    with m.If(header.type == RecordType.MASTER_CONTROL):
                        bump("records_control")
                        for i, (name, _) in enumerate(records.MASTER_CONFIG):
                            with m.If(control.apply[i]):
                                m.d.sync += self.settings[name].eq(control[name])
                        m.d.sync += self.trigger.eq((control.action & records.Action.SOFTWARE_TRIGGER) != 0)
                    with m.Else():
                        bump("records_status")
                        m.next = "QUERY"
            with m.State("QUERY"):
                m.d.comb += self.queries.valid.eq(1)
                with m.If(self.queries.ready):
                    m.next = "RECEIVE"
        return m


class MasterEndpoint(wiring.Component):
    """Stack + :class:`MasterParser` + a master status reply; in ``sync``.

    Parameters
    ----------
    config : dict
        The configuration at reset (:func:`master_config_init`).
    mac, ip, port : int
        The master's addresses (build parameters).
    buffer_depth : int
        Bytes of the receive ring (the master's records are short).

    Members
    -------
    rx : In(stream.Signature(ByteBeat))
        Frames from the MAC receive side.
    tx : Out(stream.Signature(ByteBeat))
        Frames to the MAC transmit side: ARP, ICMP echo and master status replies.
    settings, trigger
        The parser's (:class:`MasterParser`).
    status : In(layout(records.MASTER_STATUS))
        What the reply reports of the master (its configuration field by field from
        ``settings``: the owner wires it, so that the reply shows what the master obeys).
    net_counters : Out(layout(records.NET_COUNTERS))
    record_counters : Out(layout(records.MASTER_RECORD_COUNTERS))
    """

    def __init__(self, config, *, mac, ip, port, buffer_depth=2048):
        self._config = config
        self._addresses = (mac, ip, port)
        self._depth = buffer_depth
        super().__init__({
            "rx": In(stream.Signature(ByteBeat)),
            "tx": Out(stream.Signature(ByteBeat)),
            "settings": Out(MASTER_CONFIG_LAYOUT, init=config),
            "trigger": Out(1),
            "status": In(layout(records.MASTER_STATUS)),
            "net_counters": Out(layout(records.NET_COUNTERS)),
            "record_counters": Out(layout(records.MASTER_RECORD_COUNTERS)),
        })

    def elaborate(self, platform):
        m = Module()
        m.submodules.stack = stack = Stack(buffer_depth=self._depth)
        m.submodules.parser = parser = MasterParser(self._config)
        m.submodules.status_reply = reply = StatusReply(RecordType.MASTER_STATUS, _REPLY_PARTS)
        connect(m, wiring.flipped(self.rx), stack.rx)
        connect(m, stack.tx, wiring.flipped(self.tx))
        connect(m, stack.datagrams, parser.datagrams)
        connect(m, parser.queries, reply.queries)
        connect(m, reply.request, stack.reply_request)
        connect(m, reply.body, stack.reply_body)
        mac, ip, port = self._addresses
        m.d.comb += [
            stack.mac.eq(mac), stack.ip.eq(ip), stack.port.eq(port),
            self.settings.eq(parser.settings),
            self.trigger.eq(parser.trigger),
            self.net_counters.eq(stack.counters),
            self.record_counters.eq(parser.counters),
            reply.net.eq(stack.counters),
            reply.records.eq(parser.counters),
            reply.master.eq(self.status),
        ]
        return m
