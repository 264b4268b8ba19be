"""ARP (RFC 826) for IPv4 over Ethernet: which requests to answer, and the reply's fields."""

from amaranth import Module
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from ..protocol import fields
from . import ethernet
from .tap import Tap, capture

__all__ = ["PACKET", "REQUEST", "REPLY", "Checker", "reply_fields"]

PACKET = [("htype", 16), ("ptype", 16), ("hlen", 8), ("plen", 8), ("oper", 16),
          ("sha", 48), ("spa", 32), ("tha", 48), ("tpa", 32)]
REQUEST = 1
REPLY = 2
_AT = fields.size(ethernet.HEADER)


class Checker(wiring.Component):
    """Looks at the ARP packet after the Ethernet header.

    Members
    -------
    tap : In(Tap)
    ip : In(32)
        Our address.
    request_for_us : Out(1)
        An Ethernet/IPv4 ARP request whose target is ``ip``, complete in the frame.
    sha, spa : Out(48), Out(32)
        The asker's hardware and protocol addresses: where the reply goes.
    """

    tap: In(Tap())
    ip: In(32)
    request_for_us: Out(1)
    sha: Out(48)
    spa: Out(32)

    def elaborate(self, platform):
        m = Module()
        packet = capture(m, self.tap, _AT, PACKET, "arp")
        m.d.comb += [
            self.request_for_us.eq(
                (self.tap.length >= _AT + fields.size(PACKET))
                & (packet.htype == 1) & (packet.ptype == ethernet.ETHERTYPE_IPV4)
                & (packet.hlen == 6) & (packet.plen == 4)
                & (packet.oper == REQUEST) & (packet.tpa == self.ip)),
            self.sha.eq(packet.sha),
            self.spa.eq(packet.spa),
        ]
        return m


def reply_fields(our_mac, our_ip, peer):
    """The fields of our answer to ``peer`` (a :class:`~gateware.net.layouts.Peer`)."""
    return {"htype": 1, "ptype": ethernet.ETHERTYPE_IPV4, "hlen": 6, "plen": 4, "oper": REPLY,
            "sha": our_mac, "spa": our_ip, "tha": peer.mac, "tpa": peer.ip}
