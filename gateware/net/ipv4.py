"""IPv4 (RFC 791) on receive: the header checks, and the sum of the payload for the layer above."""

from amaranth import Module, Signal
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from spec import headers
from spec.wire import size

from ..wire import to_bytes
from .checksum import fold, ones_sum, word_add
from .layouts import OFFSET_BITS
from .tap import Tap, capture

__all__ = ["Checker", "header_fields"]

_AT = headers.IPV4_AT
PAYLOAD_AT = headers.IP_PAYLOAD_AT


def _words(raw_bytes):
    return [raw_bytes[i] << 8 | raw_bytes[i + 1] for i in range(0, len(raw_bytes), 2)]


class Checker(wiring.Component):
    """Looks at the IPv4 header after the Ethernet header, and sums its payload.

    Members
    -------
    tap : In(Tap)
    ip : In(32)
        Our address.
    length_ok : Out(1)
        Total length at least a header, and the frame at least that long: bytes beyond the total
        length (Ethernet padding, RFC 894 and RFC 1122) are not part of the datagram.
    version_ok, options, checksum_ok, fragment, dst_ok : Out(1)
        Version 4; a header longer than 20 bytes; the header checksum holds; MF set or a
        non-zero fragment offset; addressed to ``ip``.
    protocol : Out(8)
    src, dst : Out(32)
    payload_length : Out(OFFSET_BITS)
        Bytes after the header, by the total length (padding excluded).
    payload_sum : Out(32)
        Two's complement sum of the payload as big-endian 16-bit words (an odd last byte
        padded with zero), for the ICMP and UDP checksums.
    """

    tap: In(Tap())
    ip: In(32)
    length_ok: Out(1)
    version_ok: Out(1)
    options: Out(1)
    checksum_ok: Out(1)
    fragment: Out(1)
    dst_ok: Out(1)
    protocol: Out(8)
    src: Out(32)
    dst: Out(32)
    payload_length: Out(OFFSET_BITS)
    payload_sum: Out(32)

    def elaborate(self, platform):
        m = Module()
        tap = self.tap
        header = capture(m, tap, _AT, headers.IPV4, "ip")
        end = Signal(OFFSET_BITS + 1)
        m.d.comb += end.eq(_AT + header.total_length)

        # Both sums accumulate as the bytes pass, so that the decision after the last byte
        # needs only a fold and a compare.
        header_sum = Signal(20)
        with m.If(tap.valid):
            with m.If(tap.offset == 0):
                m.d.sync += [header_sum.eq(0), self.payload_sum.eq(0)]
            with m.Elif((tap.offset >= _AT) & (tap.offset < PAYLOAD_AT)):
                m.d.sync += header_sum.eq(word_add(header_sum, tap.data, ~tap.offset[0]))
            with m.Elif((tap.offset >= PAYLOAD_AT) & (tap.offset < end)):
                m.d.sync += self.payload_sum.eq(word_add(self.payload_sum, tap.data, ~tap.offset[0]))

        m.d.comb += [
            self.length_ok.eq((header.total_length >= size(headers.IPV4)) & (tap.length >= end)),
            self.version_ok.eq(header.version == 4),
            self.options.eq(header.ihl != 5),
            self.checksum_ok.eq(fold(header_sum) == 0xFFFF),
            self.fragment.eq(((header.flags & headers.IP_FLAG_MF) != 0) | (header.fragment_offset != 0)),
            self.dst_ok.eq(header.dst == self.ip),
            self.protocol.eq(header.protocol),
            self.src.eq(header.src),
            self.dst.eq(header.dst),
            self.payload_length.eq(header.total_length - size(headers.IPV4)),
        ]
        return m


def header_fields(protocol, payload_length, ident, src, dst):
    """Fields of a header we send (checksum included): no options, don't fragment."""
    total = payload_length + size(headers.IPV4)
    values = {"version": 4, "ihl": 5, "total_length": total, "ident": ident, "flags": headers.IP_FLAG_DF,
              "ttl": headers.IP_TTL, "protocol": protocol, "src": src, "dst": dst}
    raw = to_bytes(headers.IPV4, values)
    values["checksum"] = ~ones_sum(_words(raw))
    return values
