"""Test frames built with scapy (an oracle independent of the gateware), good and bad.

Frames run from the destination MAC to the end of the payload, as the MAC hands them to the
stack; short ones are padded to 60 bytes as a sender's NIC pads them.
"""

from scapy.layers.inet import ICMP, IP, UDP
from scapy.layers.l2 import ARP, Dot1Q, Ether
from scapy.packet import Raw

__all__ = ["Addresses", "wire", "udp", "arp_request", "icmp_echo", "BAD_FRAMES", "byte_beats"]


class Addresses:
    """Our end (the projector) and the host's end."""

    def __init__(self, mac=0x02_00_00_00_00_01, ip=0x0A_00_00_02, port=5000,
                 host_mac="02:00:00:00:00:99", host_ip="10.0.0.1", host_port=40000):
        self.mac, self.ip, self.port = mac, ip, port
        self.host_mac, self.host_ip, self.host_port = host_mac, host_ip, host_port

    @property
    def mac_str(self):
        return ":".join(f"{b:02x}" for b in self.mac.to_bytes(6, "big"))

    @property
    def ip_str(self):
        return ".".join(str(b) for b in self.ip.to_bytes(4, "big"))


def wire(packet):
    """Bytes as the MAC delivers them: padded to the 60-byte minimum."""
    raw = bytes(packet)
    return raw + bytes(max(0, 60 - len(raw)))


def udp(a, payload, *, dst_mac=None, dst_ip=None, dport=None, ip_kw=None, udp_kw=None, eth_kw=None):
    packet = (Ether(dst=dst_mac or a.mac_str, src=a.host_mac, **(eth_kw or {}))
              / IP(src=a.host_ip, dst=dst_ip or a.ip_str, **(ip_kw or {}))
              / UDP(sport=a.host_port, dport=dport or a.port, **(udp_kw or {}))
              / Raw(payload))
    return wire(packet)


def arp_request(a, *, target=None):
    return wire(Ether(dst="ff:ff:ff:ff:ff:ff", src=a.host_mac)
                / ARP(op=1, hwsrc=a.host_mac, psrc=a.host_ip, pdst=target or a.ip_str))


def icmp_echo(a, payload=b"ping", *, ident=0x1234, seq=1):
    return wire(Ether(dst=a.mac_str, src=a.host_mac) / IP(src=a.host_ip, dst=a.ip_str)
                / ICMP(type=8, id=ident, seq=seq) / Raw(payload))


def _bad_ip_checksum(a, payload):
    return udp(a, payload, ip_kw={"chksum": 0x1234})


def _bad_udp_checksum(a, payload):
    good = bytes(Ether() / IP(src=a.host_ip, dst=a.ip_str) / UDP(sport=a.host_port, dport=a.port)
                 / Raw(payload))
    checksum = int.from_bytes(good[14 + 20 + 6:14 + 20 + 8], "big")
    return udp(a, payload, udp_kw={"chksum": checksum ^ 0x00FF})


def _ip_length_long(a, payload):
    """IP total length claims more than the frame has."""
    return udp(a, payload, ip_kw={"len": 20 + 8 + len(payload) + 4})


def _udp_length_short(a, payload):
    """UDP length less than the IPv4 payload."""
    return udp(a, payload, udp_kw={"len": 8 + len(payload) - 1, "chksum": 0})


def _truncated(a, payload):
    """The frame ends before the IP total length says (bytes lost on the way)."""
    return udp(a, payload)[:-3]


def _unknown_ethertype(a, payload):
    return wire(Ether(dst=a.mac_str, src=a.host_mac, type=0x88B5) / Raw(payload))


def _vlan(a, payload):
    return wire(Ether(dst=a.mac_str, src=a.host_mac) / Dot1Q(vlan=5) / IP(src=a.host_ip, dst=a.ip_str)
                / UDP(sport=a.host_port, dport=a.port) / Raw(payload))


def _ip_options(a, payload):
    from scapy.layers.inet import IPOption_NOP
    return udp(a, payload, ip_kw={"options": [IPOption_NOP()] * 4})


#: One builder per class of bad frame: ``name -> (builder(addresses, payload), counter)``.
BAD_FRAMES = {
    "wrong_dst_mac": (lambda a, p: udp(a, p, dst_mac="02:00:00:00:00:42"), "drop_dst_mac"),
    "wrong_ip": (lambda a, p: udp(a, p, dst_ip="10.0.0.77"), "drop_ip_dst"),
    "wrong_port": (lambda a, p: udp(a, p, dport=a.port + 1), "drop_udp_port"),
    "ip_options": (_ip_options, "drop_ip_options"),
    "fragment_mf": (lambda a, p: udp(a, p, ip_kw={"flags": "MF"}), "drop_ip_fragment"),
    "fragment_offset": (lambda a, p: udp(a, p, ip_kw={"frag": 3}), "drop_ip_fragment"),
    "bad_ip_checksum": (_bad_ip_checksum, "drop_ip_checksum"),
    "bad_udp_checksum": (_bad_udp_checksum, "drop_udp_checksum"),
    "ip_length_long": (_ip_length_long, "drop_ip_length"),
    "truncated_frame": (_truncated, "drop_ip_length"),
    "udp_length_short": (_udp_length_short, "drop_udp_length"),
    "unknown_ethertype": (_unknown_ethertype, "drop_ethertype"),
    "vlan_tag": (_vlan, "drop_vlan"),
    "ip_version_6": (lambda a, p: udp(a, p, ip_kw={"version": 6}), "drop_ip_version"),
    "unknown_ip_protocol": (lambda a, p: wire(Ether(dst=a.mac_str, src=a.host_mac)
                                              / IP(src=a.host_ip, dst=a.ip_str, proto=6) / Raw(p)),
                            "drop_ip_protocol"),
    "arp_for_other": (lambda a, p: arp_request(a, target="10.0.0.55"), "drop_arp"),
}


def byte_beats(raw, bad=False):
    """A frame as :class:`gateware.mac.layouts.ByteBeat` transfers."""
    last = len(raw) - 1
    return [{"data": b, "last": int(i == last), "user": int(bad and i == last)} for i, b in enumerate(raw)]

