"""The application protocol's field definitions: the one source of truth for both ends.

Every record is a sequence of big-endian fields. Each table below lists ``(name, width in bits)``
in wire order. From a table come

- the gateware's view of received bytes (:func:`layout`, :func:`view`) and the bytes it sends
  (:func:`to_bytes`), and
- the host's encoder and decoder (:func:`pack`, :func:`unpack`), which need no Amaranth.

``docs/protocol.md`` describes the meaning of each field; the widths live only here.

The same helpers describe the network headers (Ethernet, ARP, IPv4, ICMP, UDP) in
:mod:`gateware.net`, so that the stack's parsers and reply builders share one mechanism.
"""

__all__ = [
    "MAGIC", "VERSION", "RecordType", "TriggerMode", "Action",
    "HEADER", "IMAGE", "CONTROL", "CONFIG", "NET_COUNTERS", "APP_COUNTERS", "SYSTEM_STATUS",
    "STATUS_REPLY", "size", "pack", "unpack", "layout", "view", "byte_slice", "to_bytes", "offsets",
    "image_record_length", "MAX_RECORD",
]

import enum as _enum

#: ``"DM"``: first two bytes of every record.
MAGIC = 0x444D
#: Protocol version this tree speaks; records with any other version are dropped and counted.
VERSION = 1
#: Largest record: a UDP payload inside a 9000-byte IP MTU (9000 - 20 IPv4 - 8 UDP).
MAX_RECORD = 8972


class RecordType(_enum.IntEnum):
    IMAGE = 1
    CONTROL = 2
    STATUS_QUERY = 3
    STATUS_REPLY = 4


class TriggerMode(_enum.IntEnum):
    INTERNAL = 0    # frames follow the frame period
    EXTERNAL = 1    # frames follow the trigger input
    SOFTWARE = 2    # frames follow software-trigger control records


class Action(_enum.IntFlag):
    SOFTWARE_TRIGGER = 1


#: Common header of every record.
HEADER = [
    ("magic", 16),
    ("version", 8),
    ("type", 8),
    ("length", 16),      # whole record in bytes, this header included
    ("sequence", 32),    # sender's record counter; gaps are counted as loss
]

#: Image record body (after :data:`HEADER`), followed by ``row_count * row_bytes`` pixel bytes.
IMAGE = [
    ("frame", 16),       # frame id; its low bits select the store's frame slot
    ("first_row", 16),
    ("row_count", 16),
    ("row_bytes", 16),   # must equal the DMD's columns (8-bit pixels)
]

#: Run-time configuration: the registers a control record sets (the gateware's ``Config``).
CONFIG = [
    ("bit_depth", 8),        # 1..8 planes shown per frame
    ("trigger_mode", 8),     # :class:`TriggerMode`
    ("armed", 8),            # 1: the sequencer may show frames
    ("frame_period_us", 32),
    ("exposure_us", 32),
    ("sequence_start", 16),  # first frame slot of a sequence
    ("sequence_length", 16), # slots in the sequence (1 = a single frame)
    ("mac", 48),             # our MAC address
    ("ip", 32),              # our IPv4 address
    ("port", 16),            # our UDP port
]

#: Control record body: ``apply`` bit i makes CONFIG field i take the record's value; the others
#: keep theirs. ``action`` bits are one-shot commands (:class:`Action`).
CONTROL = [("apply", 16), ("action", 8)] + CONFIG

#: Counters kept by the network stack (frames, by outcome).
NET_COUNTERS = [
    ("frames", 32),          # frames seen from the MAC
    ("accepted", 32),        # frames committed (UDP, ICMP echo, ARP request for us)
    ("drop_mac", 32),        # the MAC's verdict was bad (FCS, rx_er, runt, oversize)
    ("drop_overflow", 32),   # no room in the receive buffer
    ("drop_dst_mac", 32),
    ("drop_vlan", 32),
    ("drop_ethertype", 32),
    ("drop_arp", 32),        # ARP that is not a request for our address
    ("drop_ip_version", 32),
    ("drop_ip_options", 32),
    ("drop_ip_length", 32),  # total length against the frame
    ("drop_ip_checksum", 32),
    ("drop_ip_fragment", 32),
    ("drop_ip_dst", 32),
    ("drop_ip_protocol", 32),
    ("drop_icmp", 32),       # not an echo request, or bad ICMP checksum
    ("drop_udp_length", 32),
    ("drop_udp_port", 32),
    ("drop_udp_checksum", 32),
    ("arp_replies", 32),
    ("icmp_replies", 32),
]

#: Counters kept by the protocol parser (records, by outcome).
APP_COUNTERS = [
    ("records_image", 32),
    ("records_control", 32),
    ("records_status", 32),
    ("drop_app_magic", 32),    # not a record of this protocol
    ("drop_app_version", 32),
    ("drop_app_type", 32),
    ("drop_app_empty", 32),    # zero length or zero rows
    ("drop_app_length", 32),   # length field against datagram, or against the rows it carries
    ("drop_app_rows", 32),     # rows beyond the frame geometry, or row_bytes not the DMD's
    ("drop_app_value", 32),    # a control record setting a value out of range
    ("sequence_gaps", 32),     # records whose sequence number was not the previous + 1
    ("rows", 32),              # image rows handed to the serialiser
    ("payload_bytes", 48),     # image bytes handed on
    ("last_frame", 16),
    ("last_row", 16),
]

#: Figures the rest of the system supplies (the gateware's ``Status`` input).
SYSTEM_STATUS = [
    ("uptime_cycles", 48),     # system clock cycles since reset
    ("clock_hz", 32),
    ("triggers", 32),
    ("trigger_overruns", 32),  # triggers that came while a frame was still showing
    ("frames_shown", 32),
    ("dlpc410_state", 16),     # bit 0 INIT_ACTIVE, bit 1 RST_ACTIVE, bit 2 calibrated, ...
]

#: Status reply body (after :data:`HEADER`).
STATUS_REPLY = NET_COUNTERS + APP_COUNTERS + SYSTEM_STATUS


def size(table):
    """Bytes on the wire."""
    bits = sum(width for _, width in table)
    assert bits % 8 == 0, "a record's fields fill whole bytes"
    return bits // 8


def offsets(table):
    """Field name -> byte offset of its first byte (fields that start on a byte boundary)."""
    out, bit = {}, 0
    for name, width in table:
        if bit % 8 == 0:
            out[name] = bit // 8
        bit += width
    return out


def image_record_length(row_count, row_bytes):
    return size(HEADER) + size(IMAGE) + row_count * row_bytes


# -- host side: bytes <-> dicts ----------------------------------------------------------------

def pack(table, values):
    """``{name: int}`` -> big-endian bytes; missing fields are 0; unknown names are an error."""
    unknown = set(values) - {name for name, _ in table}
    if unknown:
        raise KeyError(f"fields not in the table: {sorted(unknown)}")
    acc = 0
    for name, width in table:
        value = int(values.get(name, 0))
        if not 0 <= value < (1 << width):
            raise ValueError(f"field {name}={value} does not fit {width} bits")
        acc = (acc << width) | value
    return acc.to_bytes(size(table), "big")


def unpack(table, raw):
    """Big-endian bytes (at least :func:`size` of them) -> ``{name: int}``."""
    n = size(table)
    if len(raw) < n:
        raise ValueError(f"need {n} bytes, got {len(raw)}")
    acc = int.from_bytes(bytes(raw[:n]), "big")
    out, shift = {}, n * 8
    for name, width in table:
        shift -= width
        out[name] = (acc >> shift) & ((1 << width) - 1)
    return out


# -- gateware side: the same tables as Amaranth layouts -----------------------------------------

def layout(table):
    """A :class:`amaranth.lib.data.StructLayout` with the table's fields.

    Fields are placed so that the Amaranth value ``Cat(byte[n-1], ..., byte[0])`` of the wire
    bytes (first byte most significant) reads as the struct: see :func:`view`.
    """
    from amaranth.lib import data
    return data.StructLayout(dict(reversed([(name, width) for name, width in table])))


def view(table, wire_bytes):
    """The struct view of ``wire_bytes`` (a list of 8-bit values, first byte on the wire first)."""
    from amaranth import Cat
    from amaranth.lib import data
    assert len(wire_bytes) == size(table)
    return data.View(layout(table), Cat(*reversed(wire_bytes)))


def byte_slice(wide, total, first, count):
    """Bytes ``first .. first + count - 1`` (wire order) of a ``total``-byte value that holds
    its first wire byte in the most significant bits, as one value in the same order."""
    return wide[8 * (total - first - count):8 * (total - first)]


def to_bytes(table, values):
    """Wire bytes (8-bit Amaranth values, first first) of fields given as ``{name: value}``;
    values are truncated or zero-extended to the field width; missing fields are 0. Each byte
    is built from the field bits it holds, so that no byte drags the whole header along."""
    from amaranth import C, Cat, Value
    parts = []  # (lsb position in the big-endian integer, value), least significant first
    position = 0
    for name, width in reversed(table):
        value = Value.cast(values.get(name, 0))
        value = value[:width] if len(value) >= width else Cat(value, C(0, width - len(value)))
        parts.append((position, value))
        position += width
    n = size(table)
    out = []
    for i in range(n):
        lo, hi = 8 * (n - 1 - i), 8 * (n - i)
        pieces = [value[max(lo, at) - at:min(hi, at + len(value)) - at]
                  for at, value in parts if at < hi and at + len(value) > lo]
        out.append(Cat(*pieces))
    return out
