"""Ethernet II: the destination filter and the EtherType of a received frame."""

from amaranth import Module
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from spec import headers
from spec.wire import size

from .tap import Tap, capture

__all__ = ["Checker"]


class Checker(wiring.Component):
    """Looks at bytes 0-13 of each frame.

    Members
    -------
    tap : In(Tap)
    mac : In(48)
        Our address.
    short : Out(1)
        The frame ended inside the Ethernet header.
    dst_ok : Out(1)
        Addressed to us or to everyone.
    vlan : Out(1)
        A VLAN tag stands where the EtherType should.
    is_ipv4, is_arp : Out(1)
    src : Out(48)
        The sender's address.

    The outputs describe the last complete frame while the stack decides on it.
    """

    tap: In(Tap())
    mac: In(48)
    short: Out(1)
    dst_ok: Out(1)
    vlan: Out(1)
    is_ipv4: Out(1)
    is_arp: Out(1)
    src: Out(48)

    def elaborate(self, platform):
        m = Module()
        header = capture(m, self.tap, 0, headers.ETHERNET, "eth")
        m.d.comb += [
            self.short.eq(self.tap.length < size(headers.ETHERNET)),
            self.dst_ok.eq((header.dst == self.mac) | (header.dst == headers.BROADCAST)),
            self.vlan.eq(sum(header.ethertype == tpid for tpid in headers.VLAN_TPIDS) != 0),
            self.is_ipv4.eq(header.ethertype == headers.ETHERTYPE_IPV4),
            self.is_arp.eq(header.ethertype == headers.ETHERTYPE_ARP),
            self.src.eq(header.src),
        ]
        return m
