"""Ethernet II: the destination filter and the EtherType of a received frame."""

from amaranth import Module
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from ..protocol import fields
from .tap import Tap, capture

__all__ = ["HEADER", "ETHERTYPE_IPV4", "ETHERTYPE_ARP", "VLAN_TPIDS", "BROADCAST", "Checker"]

HEADER = [("dst", 48), ("src", 48), ("ethertype", 16)]
ETHERTYPE_IPV4 = 0x0800
ETHERTYPE_ARP = 0x0806
#: 802.1Q, 802.1ad and the older QinQ tag: tagged frames are dropped.
VLAN_TPIDS = (0x8100, 0x88A8, 0x9100)
BROADCAST = (1 << 48) - 1


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
        header = capture(m, self.tap, 0, HEADER, "eth")
        m.d.comb += [
            self.short.eq(self.tap.length < fields.size(HEADER)),
            self.dst_ok.eq((header.dst == self.mac) | (header.dst == BROADCAST)),
            self.vlan.eq(sum(header.ethertype == tpid for tpid in VLAN_TPIDS) != 0),
            self.is_ipv4.eq(header.ethertype == ETHERTYPE_IPV4),
            self.is_arp.eq(header.ethertype == ETHERTYPE_ARP),
            self.src.eq(header.src),
        ]
        return m
