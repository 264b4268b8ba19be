"""The network stack: Ethernet, ARP, IPv4, ICMP echo and UDP in ``sync``.

Receive is store-and-forward through :class:`~gateware.net.buffer.FrameBuffer`: every byte is
written as it arrives while the per-protocol checkers (:mod:`.ethernet`, :mod:`.arp`,
:mod:`.ipv4`, :mod:`.icmp`, :mod:`.udp`) watch it pass; three cycles after the last byte (whose
``user`` bit carries the MAC's verdict) the frame is either committed, with a descriptor of
what to do with it, or rewound and counted under the first check it failed. A dispatcher then
reads committed frames back in order: UDP payloads leave on ``datagrams``, ICMP echo requests and
ARP requests become replies through :class:`~gateware.net.transmit.Transmitter`, which also takes
the application's replies.
"""

from amaranth import Cat, Module, Mux, Signal
from amaranth.lib import data, stream, wiring
from amaranth.lib.fifo import SyncFIFOBuffered
from amaranth.lib.wiring import In, Out, connect
from amaranth.utils import exact_log2

from spec import headers, records

from ..mac.layouts import ByteBeat
from ..wire import layout
from . import arp, ethernet, icmp, ipv4, udp
from .buffer import FrameBuffer
from .layouts import OFFSET_BITS, BodyByte, Datagram, Peer, ReplyKind, ReplyRequest
from .tap import Tap
from .transmit import Transmitter

__all__ = ["Stack", "DROP_CAUSES"]

#: Why a frame was dropped, in the order the checks apply: the first failing one is counted.
DROP_CAUSES = [name[len("drop_"):] for name, _ in records.NET_COUNTERS if name.startswith("drop_")]


def descriptor_layout(pointer_bits):
    """What the receive side tells the dispatcher about a committed frame."""
    return data.StructLayout({
        "kind": ReplyKind,
        "addr": pointer_bits,        # first byte to read back (UDP data or ICMP message)
        "length": OFFSET_BITS,       # bytes to read back
        "end": pointer_bits,         # one past the frame: freed when it is done
        "peer": Peer,                # where an answer goes
        "checksum": 16,              # ICMP: the request's checksum
    })


class Stack(wiring.Component):
    """Ethernet/ARP/IPv4/ICMP/UDP, receive and transmit.

    Parameters
    ----------
    buffer_depth : int
        Bytes of the receive ring (a power of 2; at least two jumbo frames keep line rate).
    descriptors : int
        Committed frames that may wait for the dispatcher.

    Members
    -------
    rx : In(stream.Signature(ByteBeat))
        Frames from the MAC (``user`` with ``last``: the MAC's verdict is bad). Ready drops for
        three cycles after each frame while the stack decides (the MAC's inter-frame gap is
        at least 20 byte times).
    tx : Out(stream.Signature(ByteBeat))
        ARP replies, ICMP echo replies and the application's replies, towards the MAC.
    mac, ip, port : In(48), In(32), In(16)
        Our addresses (a control record may change them at run time).
    datagrams : Out(stream.Signature(Datagram))
        Payloads of committed UDP datagrams to ``port``, with their sender and length.
    reply_request : In(stream.Signature(ReplyRequest))
    reply_body : In(stream.Signature(BodyByte))
        The application's UDP replies (kind UDP): destination and payload.
    counters : Out(layout(records.NET_COUNTERS))
        Frames seen, accepted, dropped per cause, replies sent.
    """

    def __init__(self, *, buffer_depth=16384, descriptors=8):
        self._depth = buffer_depth
        self._descriptors = descriptors
        super().__init__({
            "rx": In(stream.Signature(ByteBeat)),
            "tx": Out(stream.Signature(ByteBeat)),
            "mac": In(48),
            "ip": In(32),
            "port": In(16),
            "datagrams": Out(stream.Signature(Datagram)),
            "reply_request": In(stream.Signature(ReplyRequest)),
            "reply_body": In(stream.Signature(BodyByte)),
            "counters": Out(layout(records.NET_COUNTERS)),
        })

    def elaborate(self, platform):
        m = Module()
        m.submodules.buffer = buffer = FrameBuffer(self._depth)
        m.submodules.transmitter = transmitter = Transmitter(sources=2)
        desc_layout = descriptor_layout(exact_log2(self._depth) + 1)
        m.submodules.descriptors = fifo = SyncFIFOBuffered(
            width=desc_layout.size, depth=self._descriptors)
        m.submodules.eth = eth = ethernet.Checker()
        m.submodules.arp = arp_check = arp.Checker()
        m.submodules.ipv4 = ip = ipv4.Checker()
        m.submodules.icmp = icmp_check = icmp.Checker()
        m.submodules.udp = udp_check = udp.Checker()

        # The tap all checkers watch.
        tap = Tap().create()
        for checker in (eth, arp_check, ip, icmp_check, udp_check):
            connect(m, tap, checker.tap)
        m.d.comb += [
            eth.mac.eq(self.mac), arp_check.ip.eq(self.ip), ip.ip.eq(self.ip), udp_check.port.eq(self.port),
            icmp_check.payload_length.eq(ip.payload_length), icmp_check.payload_sum.eq(ip.payload_sum),
            udp_check.payload_length.eq(ip.payload_length), udp_check.payload_sum.eq(ip.payload_sum),
        ]
        for name in ("mac", "ip", "port"):
            m.d.comb += getattr(transmitter, name).eq(getattr(self, name))
        connect(m, transmitter.tx, wiring.flipped(self.tx))

        counters = self.counters
        self._receive(m, tap, buffer, fifo.w_stream, desc_layout, eth, arp_check, ip, icmp_check, udp_check,
                      counters)
        self._dispatch(m, buffer, fifo.r_stream, desc_layout, transmitter, counters)
        connect(m, wiring.flipped(self.reply_request), transmitter.requests[1])
        connect(m, wiring.flipped(self.reply_body), transmitter.bodies[1])
        return m

    def _receive(self, m, tap, buffer, descriptors, desc_layout, eth, arp_check, ip, icmp_check, udp_check,
                 counters):
        offset = Signal(OFFSET_BITS)
        mac_bad = Signal()
        cause = Signal(range(len(DROP_CAUSES)))
        accept = Signal()
        descriptor = Signal(desc_layout)
        taken = self.rx.valid & self.rx.ready
        m.d.comb += [
            tap.valid.eq(taken),
            tap.data.eq(self.rx.payload.data),
            tap.offset.eq(offset),
            buffer.write.valid.eq(taken),
            buffer.write.payload.eq(self.rx.payload.data),
        ]
        with m.If(taken):
            m.d.sync += offset.eq(Mux(offset.all(), offset, offset + 1))

        start = buffer.frame_start
        # The first failing check names the cause.
        is_ip = eth.is_ipv4
        is_icmp = ip.protocol == headers.IP_PROTOCOL_ICMP
        is_udp = ip.protocol == headers.IP_PROTOCOL_UDP
        checks = [
            (mac_bad, "mac"),
            (buffer.overflow, "overflow"),
            (eth.short, "ethertype"),
            (~eth.dst_ok, "dst_mac"),
            (eth.vlan, "vlan"),
            (eth.is_arp & ~arp_check.request_for_us, "arp"),
            (~eth.is_arp & ~is_ip, "ethertype"),
            (is_ip & ~ip.length_ok, "ip_length"),
            (is_ip & ~ip.version_ok, "ip_version"),
            (is_ip & ip.options, "ip_options"),
            (is_ip & ~ip.checksum_ok, "ip_checksum"),
            (is_ip & ip.fragment, "ip_fragment"),
            (is_ip & ~ip.dst_ok, "ip_dst"),
            (is_ip & is_icmp & ~(icmp_check.echo_request & icmp_check.checksum_ok), "icmp"),
            (is_ip & is_udp & ~udp_check.length_ok, "udp_length"),
            (is_ip & is_udp & ~udp_check.port_ok, "udp_port"),
            (is_ip & is_udp & ~udp_check.checksum_ok, "udp_checksum"),
            (is_ip & ~is_icmp & ~is_udp, "ip_protocol"),
        ]
        failed = Signal(len(checks))
        with m.FSM():
            with m.State("RECEIVE"):
                m.d.comb += self.rx.ready.eq(1)
                with m.If(taken & self.rx.payload.last):
                    m.d.sync += [
                        tap.length.eq(Mux(offset.all(), offset, offset + 1)),
                        mac_bad.eq(self.rx.payload.user),
                        offset.eq(0),
                    ]
                    m.next = "EVALUATE"
            with m.State("EVALUATE"):
                m.d.sync += failed.eq(Cat(condition for condition, _ in checks))
                m.next = "DECIDE"
            with m.State("DECIDE"):
                m.d.sync += [accept.eq(1), descriptor.end.eq(buffer.write_pointer)]
                for i, (_, name) in enumerate(checks):
                    with (m.If if i == 0 else m.Elif)(failed[i]):
                        m.d.sync += [accept.eq(0), cause.eq(DROP_CAUSES.index(name))]
                # What to do with the frame if it is kept, and where an answer goes.
                m.d.sync += [
                    descriptor.peer.mac.eq(eth.src),
                    descriptor.peer.ip.eq(ip.src),
                    descriptor.peer.port.eq(udp_check.src_port),
                    descriptor.checksum.eq(icmp_check.checksum),
                ]
                with m.If(eth.is_arp):
                    m.d.sync += [
                        descriptor.kind.eq(ReplyKind.ARP),
                        descriptor.peer.mac.eq(arp_check.sha),
                        descriptor.peer.ip.eq(arp_check.spa),
                    ]
                with m.Elif(is_icmp):
                    m.d.sync += [
                        descriptor.kind.eq(ReplyKind.ICMP),
                        descriptor.addr.eq(start + headers.IP_PAYLOAD_AT),
                        descriptor.length.eq(ip.payload_length),
                    ]
                with m.Else():
                    m.d.sync += [
                        descriptor.kind.eq(ReplyKind.UDP),
                        descriptor.addr.eq(start + headers.UDP_PAYLOAD_AT),
                        descriptor.length.eq(udp_check.data_length),
                    ]
                m.next = "COMMIT"
            with m.State("COMMIT"):
                # a frame is kept only if its descriptor fits: written now or dropped
                keep = accept & descriptors.ready
                m.d.comb += [
                    descriptors.valid.eq(keep),
                    descriptors.payload.eq(descriptor),
                    buffer.commit.eq(keep),
                    buffer.discard.eq(~keep),
                ]
                m.d.sync += counters.frames.eq(counters.frames + 1)
                with m.If(keep):
                    m.d.sync += counters.accepted.eq(counters.accepted + 1)
                with m.Elif(accept):
                    counter = counters["drop_overflow"]
                    m.d.sync += counter.eq(counter + 1)
                with m.Else():
                    for i, name in enumerate(DROP_CAUSES):
                        with m.If(cause == i):
                            counter = counters[f"drop_{name}"]
                            m.d.sync += counter.eq(counter + 1)
                m.next = "RECEIVE"

    def _dispatch(self, m, buffer, descriptors, desc_layout, transmitter, counters):
        descriptor = Signal(desc_layout)
        request = transmitter.requests[0]
        body = transmitter.bodies[0]
        index = Signal(3)
        reply_checksum = Signal(16)
        m.d.comb += [
            request.payload.kind.eq(descriptor.kind),
            request.payload.peer.eq(descriptor.peer),
            request.payload.length.eq(descriptor.length),
            reply_checksum.eq(icmp.reply_checksum(descriptor.checksum)),
            buffer.read.payload.addr.eq(descriptor.addr),
            buffer.read.payload.length.eq(descriptor.length),
            buffer.release_to.eq(descriptor.end),
        ]
        out = buffer.data
        with m.FSM():
            with m.State("IDLE"):
                m.d.comb += descriptors.ready.eq(1)
                with m.If(descriptors.valid):
                    m.d.sync += descriptor.eq(descriptors.payload)
                    m.next = "START"
            with m.State("START"):
                with m.If(descriptor.kind == ReplyKind.UDP):
                    m.next = "READ"
                with m.Else():
                    m.d.comb += request.valid.eq(1)
                    with m.If(request.ready):
                        with m.If(descriptor.kind == ReplyKind.ARP):
                            m.d.sync += counters.arp_replies.eq(counters.arp_replies + 1)
                            m.next = "RELEASE"
                        with m.Else():
                            m.d.sync += counters.icmp_replies.eq(counters.icmp_replies + 1)
                            m.next = "READ"
            with m.State("READ"):
                m.d.comb += buffer.read.valid.eq(1)
                m.d.sync += index.eq(0)
                with m.If(buffer.read.ready):
                    m.next = "STREAM"
            with m.State("STREAM"):
                with m.If(descriptor.kind == ReplyKind.UDP):
                    m.d.comb += [
                        self.datagrams.valid.eq(out.valid),
                        self.datagrams.payload.data.eq(out.payload.data),
                        self.datagrams.payload.last.eq(out.payload.last),
                        self.datagrams.payload.length.eq(descriptor.length),
                        self.datagrams.payload.peer.eq(descriptor.peer),
                        out.ready.eq(self.datagrams.ready),
                    ]
                with m.Else():
                    # The echo request's message, turned into the reply: new type, new checksum.
                    m.d.comb += [
                        body.valid.eq(out.valid),
                        body.payload.data.eq(out.payload.data),
                        body.payload.last.eq(out.payload.last),
                        out.ready.eq(body.ready),
                    ]
                    with m.Switch(index):
                        with m.Case(0):
                            m.d.comb += body.payload.data.eq(headers.ICMP_ECHO_REPLY)
                        with m.Case(2):
                            m.d.comb += body.payload.data.eq(reply_checksum[8:])
                        with m.Case(3):
                            m.d.comb += body.payload.data.eq(reply_checksum[:8])
                with m.If(out.valid & out.ready):
                    m.d.sync += index.eq(Mux(index == 4, 4, index + 1))
                    with m.If(out.payload.last):
                        m.next = "RELEASE"
            with m.State("RELEASE"):
                m.d.comb += buffer.release.eq(1)
                m.next = "IDLE"
