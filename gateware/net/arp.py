"""ARP (RFC 826) for IPv4 over Ethernet: which requests to answer, and the reply's fields."""

from amaranth import Module
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from spec import headers
from spec.wire import size

from .tap import Tap, capture

__all__ = ["Checker", "reply_fields"]



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
        packet = capture(m, self.tap, headers.ARP_AT, headers.ARP, "arp")
        m.d.comb += [
            self.request_for_us.eq(
                (self.tap.length >= headers.ARP_AT + size(headers.ARP))
                & (packet.htype == 1) & (packet.ptype == headers.ETHERTYPE_IPV4)
                & (packet.hlen == 6) & (packet.plen == 4)
                & (packet.oper == headers.ARP_REQUEST) & (packet.tpa == self.ip)),
            self.sha.eq(packet.sha),
            self.spa.eq(packet.spa),
        ]
        return m


def reply_fields(our_mac, our_ip, peer):
    """The fields of our answer to ``peer`` (a :class:`~gateware.net.layouts.Peer`)."""
    return {"htype": 1, "ptype": headers.ETHERTYPE_IPV4, "hlen": 6, "plen": 4, "oper": headers.ARP_REPLY,
            "sha": our_mac, "spa": our_ip, "tha": peer.mac, "tpa": peer.ip}
