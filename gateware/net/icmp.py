"""ICMP (RFC 792) echo: which messages to answer, and the checksum of the answer."""

from amaranth import Module
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from spec import headers

from .checksum import fold
from .layouts import OFFSET_BITS
from .tap import Tap, capture

__all__ = ["Checker", "reply_checksum"]



class Checker(wiring.Component):
    """Looks at the ICMP message after the IPv4 header.

    Members
    -------
    tap : In(Tap)
    payload_length : In(OFFSET_BITS)
    payload_sum : In(32)
        From :class:`gateware.net.ipv4.Checker`.
    echo_request : Out(1)
        Type 8, code 0, long enough.
    checksum_ok : Out(1)
    checksum : Out(16)
        The received checksum, from which the reply's follows.
    """

    tap: In(Tap())
    payload_length: In(OFFSET_BITS)
    payload_sum: In(32)
    echo_request: Out(1)
    checksum_ok: Out(1)
    checksum: Out(16)

    def elaborate(self, platform):
        m = Module()
        header = capture(m, self.tap, headers.IP_PAYLOAD_AT, headers.ICMP, "icmp")
        m.d.comb += [
            self.echo_request.eq((header.type == headers.ICMP_ECHO_REQUEST) & (header.code == 0)
                                 & (self.payload_length >= headers.ICMP_MIN_ECHO)),
            self.checksum_ok.eq(fold(self.payload_sum) == 0xFFFF),
            self.checksum.eq(header.checksum),
        ]
        return m


def reply_checksum(request_checksum):
    """The echo reply's checksum: the request's with the type word 0x0800 taken out (RFC 1624)."""
    return fold(request_checksum + ((headers.ICMP_ECHO_REQUEST - headers.ICMP_ECHO_REPLY) << 8))
