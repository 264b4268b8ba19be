"""The projector's network endpoint: the network stack with the application protocol behind it.

What sits between the MAC (a :class:`~gateware.mac.layouts.ByteBeat` stream each way) and the
bit-plane serialiser, the sequencer and the status sources; all in ``sync``. The
:class:`~gateware.protocol.port.EthernetPort` puts the MACs around it.
"""

from amaranth import Module
from amaranth.lib import stream, wiring
from amaranth.lib.wiring import In, Out, connect

from spec import records

from ..mac.layouts import ByteBeat
from ..net.stack import Stack
from ..registers import Registers
from ..wire import layout
from .layouts import pixel_layout
from .parser import CONFIG_LAYOUT, ENTRY_LAYOUT, Parser, config_init
from .rows import RowAssembler
from .status import StatusReply

__all__ = ["Endpoint", "Config", "Status"]

#: The run-time configuration the endpoint drives (fields: :data:`records.CONFIG`).
Config = CONFIG_LAYOUT
#: The figures the rest of the system reports through status replies (:data:`records.SYSTEM_STATUS`).
Status = layout(records.SYSTEM_STATUS)


class Endpoint(wiring.Component):
    """Stack + protocol parser + row assembler + status reply.

    Parameters
    ----------
    dmd : :class:`spec.facts.DmdType`
    mac, ip, port : int
        Addresses at reset (build parameters); a control record may change them.
    armed : bool
        Whether triggers reach the sequencer at reset; a control record may change it.
    frame_bits : int
        Width of the frame tag on ``pixels``.
    buffer_depth : int
        Bytes of the receive ring.
    beats : int
        DCLK beats per ``dmd`` cycle of the sequencer (see :class:`~gateware.protocol.parser.Parser`).

    Members
    -------
    rx : In(stream.Signature(ByteBeat))
        Frames from the MAC receive side (crossed into ``sync``).
    tx : Out(stream.Signature(ByteBeat))
        Frames to the MAC transmit side.
    pixels : Out(stream.Signature(pixel_layout(dmd, 1, frame_bits)))
        Image rows for :class:`gateware.bitplane.Serialiser` (``lanes=1``).
    settings : Out(Config)
        Run-time configuration for the sequencer and store (reset value: the build parameters).
    trigger : Out(1)
        Software trigger pulse.
    registers : Out(stream.Signature(Registers))
        The sequencer's register set of each valid sequencer record.
    entries : Out(stream.Signature(ENTRY_LAYOUT))
        Each valid sequence entry record, for the store's entry table.
    sequence_start : Out(1)
        Pulse: play the sequence's entries from the first.
    status : In(Status)
        Figures from the rest of the system, reported in status replies.
    net_counters : Out(layout(records.NET_COUNTERS))
    app_counters : Out(layout(records.APP_COUNTERS))
    """

    def __init__(self, dmd, *, mac, ip, port, armed=False, frame_bits=4, buffer_depth=16384, beats=1):
        self._beats = beats
        self._dmd = dmd
        self._config = config_init(mac=mac, ip=ip, port=port, armed=armed)
        self._frame_bits = frame_bits
        self._depth = buffer_depth
        super().__init__({
            "rx": In(stream.Signature(ByteBeat)),
            "tx": Out(stream.Signature(ByteBeat)),
            "pixels": Out(stream.Signature(pixel_layout(dmd, 1, frame_bits))),
            "settings": Out(Config, init=self._config),
            "trigger": Out(1),
            "registers": Out(stream.Signature(Registers)),
            "entries": Out(stream.Signature(ENTRY_LAYOUT)),
            "sequence_start": Out(1),
            "status": In(Status),
            "net_counters": Out(layout(records.NET_COUNTERS)),
            "app_counters": Out(layout(records.APP_COUNTERS)),
        })

    def elaborate(self, platform):
        m = Module()
        m.submodules.stack = stack = Stack(buffer_depth=self._depth)
        m.submodules.parser = parser = Parser(self._dmd, self._config, beats=self._beats)
        m.submodules.rows = rows = RowAssembler(self._dmd, frame_bits=self._frame_bits)
        m.submodules.status_reply = reply = StatusReply()

        connect(m, wiring.flipped(self.rx), stack.rx)
        connect(m, stack.tx, wiring.flipped(self.tx))
        connect(m, stack.datagrams, parser.datagrams)
        connect(m, parser.pieces, rows.pieces)
        connect(m, rows.pixels, wiring.flipped(self.pixels))
        connect(m, parser.queries, reply.queries)
        connect(m, parser.registers, wiring.flipped(self.registers))
        connect(m, parser.entries, wiring.flipped(self.entries))
        connect(m, reply.request, stack.reply_request)
        connect(m, reply.body, stack.reply_body)
        m.d.comb += [
            stack.mac.eq(parser.settings.mac),
            stack.ip.eq(parser.settings.ip),
            stack.port.eq(parser.settings.port),
            self.settings.eq(parser.settings),
            self.trigger.eq(parser.trigger),
            self.sequence_start.eq(parser.sequence_start),
            reply.net.eq(stack.counters),
            reply.app.eq(self.app_counters),
            reply.system.eq(self.status),
            self.net_counters.eq(stack.counters),
            self.app_counters.dmd_columns.eq(self._dmd.columns),
            self.app_counters.dmd_rows.eq(self._dmd.rows),
        ]
        for source, table in ((parser.counters, records.RECORD_COUNTERS), (rows.counters, records.ROW_COUNTERS)):
            m.d.comb += [self.app_counters[name].eq(source[name]) for name, _ in table]
        return m
