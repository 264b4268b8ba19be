"""The network headers the stack reads and writes: one table each, and their constants.

Tables as in :mod:`spec.wire` (``(name, width in bits)``, wire order); offsets are bytes from the
first byte of the Ethernet frame. The gateware's checkers and reply builders (:mod:`gateware.net`)
and the reference model (:mod:`sim.models.net_model`) both take them from here.
"""

from .wire import size

__all__ = [
    "ETHERNET", "ETHERTYPE_IPV4", "ETHERTYPE_ARP", "VLAN_TPIDS", "BROADCAST",
    "ARP", "ARP_REQUEST", "ARP_REPLY", "ARP_AT",
    "IPV4", "IP_PROTOCOL_ICMP", "IP_PROTOCOL_UDP", "IP_FLAG_MF", "IP_FLAG_DF", "IP_TTL", "IPV4_AT",
    "IP_PAYLOAD_AT", "MIN_FRAME",
    "ICMP", "ICMP_ECHO_REQUEST", "ICMP_ECHO_REPLY", "ICMP_MIN_ECHO",
    "UDP", "UDP_PAYLOAD_AT",
]

# -- Ethernet II (IEEE 802.3) ------------------------------------------------------------------
ETHERNET = [("dst", 48), ("src", 48), ("ethertype", 16)]
ETHERTYPE_IPV4 = 0x0800
ETHERTYPE_ARP = 0x0806
#: 802.1Q, 802.1ad and the older QinQ tag: tagged frames are dropped.
VLAN_TPIDS = (0x8100, 0x88A8, 0x9100)
BROADCAST = (1 << 48) - 1
#: Shortest Ethernet frame without FCS; shorter packets arrive padded to it.
MIN_FRAME = 60

# -- ARP (RFC 826), IPv4 over Ethernet ---------------------------------------------------------
ARP = [("htype", 16), ("ptype", 16), ("hlen", 8), ("plen", 8), ("oper", 16),
       ("sha", 48), ("spa", 32), ("tha", 48), ("tpa", 32)]
ARP_REQUEST = 1
ARP_REPLY = 2
ARP_AT = size(ETHERNET)

# -- IPv4 (RFC 791) ----------------------------------------------------------------------------
IPV4 = [("version", 4), ("ihl", 4), ("tos", 8), ("total_length", 16), ("ident", 16),
        ("flags", 3), ("fragment_offset", 13), ("ttl", 8), ("protocol", 8), ("checksum", 16),
        ("src", 32), ("dst", 32)]
IP_PROTOCOL_ICMP = 1
IP_PROTOCOL_UDP = 17
IP_FLAG_MF = 0b001
IP_FLAG_DF = 0b010
IP_TTL = 64
IPV4_AT = size(ETHERNET)
IP_PAYLOAD_AT = IPV4_AT + size(IPV4)

# -- ICMP (RFC 792) echo -----------------------------------------------------------------------
ICMP = [("type", 8), ("code", 8), ("checksum", 16)]
ICMP_ECHO_REQUEST = 8
ICMP_ECHO_REPLY = 0
#: Echo messages carry an identifier and a sequence number after the header.
ICMP_MIN_ECHO = size(ICMP) + 4

# -- UDP (RFC 768) -----------------------------------------------------------------------------
UDP = [("src_port", 16), ("dst_port", 16), ("length", 16), ("checksum", 16)]
UDP_PAYLOAD_AT = IP_PAYLOAD_AT + size(UDP)
