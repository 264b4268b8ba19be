"""UDP (RFC 768) on receive: port, length and checksum with the IPv4 pseudo-header."""

from amaranth import Module, Signal
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from spec import headers
from spec.wire import offsets, size

from .checksum import fold, word_add
from .layouts import OFFSET_BITS
from .tap import Tap, capture

__all__ = ["Checker"]



class Checker(wiring.Component):
    """Looks at the UDP header after the IPv4 header.

    Members
    -------
    tap : In(Tap)
    port : In(16)
        Our port.
    payload_length, payload_sum : In
        From :class:`gateware.net.ipv4.Checker`.
    length_ok : Out(1)
        The UDP length equals the IPv4 payload and leaves at least one byte of data
        (an empty datagram carries no record).
    port_ok : Out(1)
    checksum_ok : Out(1)
        No checksum sent (zero), or it holds over the pseudo-header, header and data.
    src_port : Out(16)
    data_length : Out(OFFSET_BITS)
        Bytes of application data.
    """

    tap: In(Tap())
    port: In(16)
    payload_length: In(OFFSET_BITS)
    payload_sum: In(32)
    length_ok: Out(1)
    port_ok: Out(1)
    checksum_ok: Out(1)
    src_port: Out(16)
    data_length: Out(OFFSET_BITS)

    def elaborate(self, platform):
        m = Module()
        header = capture(m, self.tap, headers.IP_PAYLOAD_AT, headers.UDP, "udp")
        # The pseudo-header's addresses and UDP length, summed as their bytes pass (the
        # protocol number is a constant).
        pseudo = Signal(20)
        tap = self.tap
        addresses = offsets(headers.IPV4)["src"] + headers.IPV4_AT
        length_at = headers.IP_PAYLOAD_AT + offsets(headers.UDP)["length"]
        with m.If(tap.valid):
            with m.If(tap.offset == 0):
                m.d.sync += pseudo.eq(headers.IP_PROTOCOL_UDP)
            with m.Elif(((tap.offset >= addresses) & (tap.offset < addresses + 8))
                        | (tap.offset == length_at) | (tap.offset == length_at + 1)):
                m.d.sync += pseudo.eq(word_add(pseudo, tap.data, ~tap.offset[0]))
        m.d.comb += [
            self.length_ok.eq((header.length > size(headers.UDP))
                              & (header.length == self.payload_length)),
            self.port_ok.eq(header.dst_port == self.port),
            self.checksum_ok.eq((header.checksum == 0) | (fold(self.payload_sum + pseudo) == 0xFFFF)),
            self.src_port.eq(header.src_port),
            self.data_length.eq(header.length - size(headers.UDP)),
        ]
        return m
