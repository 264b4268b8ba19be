"""Layouts shared by the stack's parts and its users: the byte tap, datagrams, reply requests."""

from amaranth.lib import data, enum

__all__ = ["MAX_FRAME", "OFFSET_BITS", "Peer", "Datagram", "ReplyKind", "ReplyRequest", "BodyByte"]

#: Longest frame the stack takes (destination MAC to end of payload, jumbo, no FCS).
MAX_FRAME = 9014
#: Width of byte offsets inside a frame.
OFFSET_BITS = 14


class Peer(data.Struct):
    """Where a datagram came from, and so where its answer goes."""
    mac: 48
    ip: 32
    port: 16


class Datagram(data.Struct):
    """One byte of a committed UDP payload; ``peer`` and ``length`` (payload bytes) hold for
    the whole datagram."""
    data: 8
    last: 1
    length: OFFSET_BITS
    peer: Peer


class ReplyKind(enum.Enum, shape=2):
    ARP = 0
    ICMP = 1
    UDP = 2


class ReplyRequest(data.Struct):
    """A frame to send: its kind, destination and body length (bytes after the headers the
    transmitter writes: none for ARP, the ICMP message for ICMP, the UDP payload for UDP)."""
    kind: ReplyKind
    peer: Peer
    length: OFFSET_BITS


class BodyByte(data.Struct):
    data: 8
    last: 1
