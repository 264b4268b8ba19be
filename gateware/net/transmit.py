"""The transmit side of the stack: frames built from a request and a body, one source at a time.

Each source offers a :class:`~gateware.net.layouts.ReplyRequest` and, for ICMP and UDP, a body
stream; the transmitter writes the Ethernet, ARP, IPv4 (checksum computed here) and UDP headers
itself, then passes the body through. Sources take turns frame by frame.
"""

from amaranth import Array, Cat, Module, Mux, Signal
from amaranth.lib import stream, wiring
from amaranth.lib.wiring import In, Out

from spec import headers
from spec.wire import size

from ..mac.layouts import ByteBeat
from ..wire import to_bytes
from . import arp, ipv4
from .layouts import BodyByte, ReplyKind, ReplyRequest

__all__ = ["Transmitter"]


class Transmitter(wiring.Component):
    """Arbitrates ``sources`` reply sources onto one byte stream towards the MAC.

    Members
    -------
    mac, ip, port : In(48), In(32), In(16)
        Our addresses, written into every frame (as they were when its request was taken).
    requests : In(stream.Signature(ReplyRequest)).array(sources)
        A frame to send. The request is taken when its frame starts.
    bodies : In(stream.Signature(BodyByte)).array(sources)
        Exactly ``length`` bytes per ICMP or UDP request, ``last`` on the final one (ICMP: the
        whole message, header included; UDP: the payload). None for ARP.
    tx : Out(stream.Signature(ByteBeat))
        Frames from the destination MAC on; the MAC pads them and adds the FCS. ``user`` with
        ``last`` asks the MAC to abort a frame whose body did not match its length.
    """

    def __init__(self, sources=2):
        self._sources = sources
        super().__init__({
            "mac": In(48),
            "ip": In(32),
            "port": In(16),
            "requests": In(stream.Signature(ReplyRequest)).array(sources),
            "bodies": In(stream.Signature(BodyByte)).array(sources),
            "tx": Out(stream.Signature(ByteBeat)),
        })

    def elaborate(self, platform):
        m = Module()
        n = self._sources
        request = Signal(ReplyRequest)
        # our addresses, taken with the request: a frame's header is built from one set of them
        # even if the host changes them while it is sent
        mac, ip, port = Signal.like(self.mac), Signal.like(self.ip), Signal.like(self.port)
        selected = Signal(range(n))
        turn = Signal(range(n))
        ident = Signal(16)
        index = Signal(range(64))
        sent = Signal.like(request.length)

        is_arp = request.kind == ReplyKind.ARP
        is_udp = request.kind == ReplyKind.UDP
        ip_payload = Mux(is_udp, request.length + size(headers.UDP), request.length)
        eth_bytes = to_bytes(headers.ETHERNET, {
            "dst": request.peer.mac, "src": mac,
            "ethertype": Mux(is_arp, headers.ETHERTYPE_ARP, headers.ETHERTYPE_IPV4)})
        arp_bytes = to_bytes(headers.ARP, arp.reply_fields(mac, ip, request.peer))
        ip_bytes = to_bytes(headers.IPV4, ipv4.header_fields(
            Mux(is_udp, headers.IP_PROTOCOL_UDP, headers.IP_PROTOCOL_ICMP), ip_payload, ident, ip,
            request.peer.ip))
        udp_bytes = to_bytes(headers.UDP, {
            "src_port": port, "dst_port": request.peer.port,
            "length": request.length + size(headers.UDP)})
        # An ARP packet is as long as the IPv4 and UDP headers together: one 42-byte header table.
        header = Array([*eth_bytes, *(Mux(is_arp, a, b)
                                      for a, b in zip(arp_bytes, ip_bytes + udp_bytes, strict=True))])
        header_end = Mux(request.kind == ReplyKind.ICMP,
                         headers.IP_PAYLOAD_AT, len(header))

        with m.FSM():
            with m.State("IDLE"):
                # Round robin: source ``turn`` first, then the ones after it (later
                # assignments win, so the nearest to ``turn`` is assigned last).
                valid = Cat(r.valid for r in self.requests)
                for distance in reversed(range(n)):
                    for i in range(n):
                        with m.If((turn == (i - distance) % n) & valid[i]):
                            m.d.sync += selected.eq(i)
                with m.If(valid.any()):
                    m.next = "TAKE"
            with m.State("TAKE"):
                for i, source in enumerate(self.requests):
                    with m.If(selected == i):
                        m.d.comb += source.ready.eq(1)
                        m.d.sync += request.eq(source.payload)
                m.d.sync += [
                    mac.eq(self.mac), ip.eq(self.ip), port.eq(self.port),
                    index.eq(0),
                    sent.eq(0),
                    turn.eq(Mux(selected == n - 1, 0, selected + 1)),
                ]
                m.next = "HEADER"
            with m.State("HEADER"):
                header_last = index == header_end - 1
                m.d.comb += [
                    self.tx.valid.eq(1),
                    self.tx.payload.data.eq(header[index]),
                    self.tx.payload.last.eq(header_last & is_arp),
                ]
                with m.If(self.tx.ready):
                    m.d.sync += index.eq(index + 1)
                    with m.If(header_last):
                        with m.If(is_arp):
                            m.next = "IDLE"
                        with m.Else():
                            m.d.sync += ident.eq(ident + 1)
                            m.next = "BODY"
            with m.State("BODY"):
                for i, body in enumerate(self.bodies):
                    with m.If(selected == i):
                        m.d.comb += [
                            self.tx.valid.eq(body.valid),
                            self.tx.payload.data.eq(body.payload.data),
                            self.tx.payload.last.eq(body.payload.last),
                            # a body that ends off its announced length would make a wrong
                            # frame: ask the MAC to abort it
                            self.tx.payload.user.eq(body.payload.last & (sent != request.length - 1)),
                            body.ready.eq(self.tx.ready),
                        ]
                        with m.If(body.valid & self.tx.ready):
                            m.d.sync += sent.eq(sent + 1)
                            with m.If(body.payload.last):
                                m.next = "IDLE"
        return m
