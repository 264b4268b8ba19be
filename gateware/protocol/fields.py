"""The application protocol's field definitions: the one source of truth for both ends.

Every record is a sequence of big-endian fields. Each table below lists ``(name, width in bits)``
in wire order. From a table come

- the gateware's view of received bytes (:func:`layout`, :func:`view`) and the bytes it sends
  (:func:`to_bytes`), and
- the host's encoder and decoder (:func:`pack`, :func:`unpack`), plain Python on ints (the
  sequencer record's table and checks come from the gateware's register struct, so this module
  imports Amaranth's data layouts).

``docs/protocol.md`` describes the meaning of each field; the widths live only here.

The same helpers describe the network headers (Ethernet, ARP, IPv4, ICMP, UDP) in
:mod:`gateware.net`, so that the stack's parsers and reply builders share one mechanism.

One authority per setting: the sequencer's run-time registers
(:class:`gateware.dlpc410.params.Registers`: trigger mode, plane durations, reset mode, ...) are
set only by the sequencer record (:data:`SEQUENCER`, derived from that struct, so that a field
added there is on the wire with no edit here); the control record (:data:`CONFIG`) sets what the
rest of the projector uses: the store's bit depth and sequence, arming, the network addresses.
"""

__all__ = [
    "MAGIC", "VERSION", "RecordType", "Action",
    "HEADER", "IMAGE", "CONTROL", "CONFIG", "SEQUENCER", "NET_COUNTERS", "APP_COUNTERS",
    "SYSTEM_STATUS", "STATUS_REPLY", "size", "pack", "unpack", "layout", "view", "byte_slice",
    "to_bytes", "offsets", "image_record_length", "MAX_RECORD",
    "register_wire", "wire_registers", "registers_bits", "register_faults",
]

import enum as _enum
import functools as _functools
import operator as _operator

from amaranth.lib import data as _data

from ..dlpc410.params import Registers as _Registers
from ..dlpc410.params import TriggerMode as _TriggerMode

#: ``"DM"``: first two bytes of every record.
MAGIC = 0x444D
#: Protocol version this tree speaks; records with any other version are dropped and counted.
VERSION = 2
#: Largest record: a UDP payload inside a 9000-byte IP MTU (9000 - 20 IPv4 - 8 UDP).
MAX_RECORD = 8972


class RecordType(_enum.IntEnum):
    IMAGE = 1
    CONTROL = 2
    STATUS_QUERY = 3
    STATUS_REPLY = 4
    SEQUENCER = 5


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
    ("bit_depth", 8),        # 1..8 planes stored per frame
    ("armed", 8),            # 1: triggers reach the sequencer; 0: every trigger source is ignored
    ("sequence_length", 16), # frame slots in the sequence (1 = a single frame, streamed)
    ("mac", 48),             # our MAC address
    ("ip", 32),              # our IPv4 address
    ("port", 16),            # our UDP port
]

#: Control record body: ``apply`` bit i makes CONFIG field i take the record's value; the others
#: keep theirs. ``action`` bits are one-shot commands (:class:`Action`).
CONTROL = [("apply", 16), ("action", 8)] + CONFIG

_REGISTERS = _data.Layout.cast(_Registers)

#: Sequencer record body: every field of :class:`gateware.dlpc410.params.Registers`, in the
#: struct's order, each widened to whole bytes (the high bits must be zero). An enum field carries
#: its value; ``order_table`` carries entry ``j`` in bits ``3j..3j+2``.
SEQUENCER = [(name, -(-field.width // 8) * 8) for name, field in _REGISTERS]

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
    ("records_control", 32),   # control records applied
    ("records_sequencer", 32), # sequencer records passed on (applied when the sequencer rests)
    ("records_status", 32),
    ("drop_app_magic", 32),    # not a record of this protocol
    ("drop_app_version", 32),
    ("drop_app_type", 32),
    ("drop_app_empty", 32),    # zero length or zero rows
    ("drop_app_length", 32),   # length field against datagram, or against the rows it carries
    ("drop_app_rows", 32),     # rows beyond the frame geometry, or row_bytes not the DMD's
    ("drop_app_value", 32),    # a control or sequencer record with a value it cannot obey
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
    ("triggers", 32),          # triggers obeyed
    ("trigger_overruns", 32),  # triggers that came while a frame was still showing
    ("frames_shown", 32),
    ("dlpc410_state", 16),     # bits: 0 INIT_ACTIVE, 1 RST_ACTIVE, 2 ECP2_FINISHED, 3 DDR2 calibrated, 4-6 link
    ("triggers_early", 32),    # triggers before the DLPC410 finished initialising
    ("pulses_late", 32),       # clocking pulses made after their time
    ("row_underruns", 32),     # row loads that waited for the store
    ("frames_bad_depth", 32),  # frames offered with a bit depth outside 1..8
    ("registers_applied", 32), # sequencer register sets taken by the sequencer
    ("registers_superseded", 32),  # register sets replaced by a newer one before the sequencer took them
    ("mac_good", 32),          # frames on the receive pins, by the MAC's verdict
    ("mac_bad_fcs", 32),
    ("mac_rx_er", 32),
    ("mac_runt", 32),
    ("mac_oversize", 32),
    ("mac_preamble", 32),
    ("mac_rx_dropped", 32),    # dropped whole: no room in the receive FIFO
    ("mac_tx_underruns", 32),  # replies aborted on the transmit pins
    ("store_frames_complete", 32),   # frames whose every row arrived
    ("store_frames_replaced", 32),   # complete, replaced unshown by a newer one
    ("store_frames_abandoned", 32),  # incomplete, abandoned for a newer frame (a lost record)
    ("store_rows_refused", 32),      # rows the store refused (outside, stale, shown, duplicate, no slot)
]

#: Status reply body (after :data:`HEADER`).
STATUS_REPLY = NET_COUNTERS + APP_COUNTERS + SYSTEM_STATUS


def register_wire(values):
    """Register values (a dict as for ``Registers.const``: enums, lists, ints) -> the sequencer
    record's field values (ints)."""
    bits = _REGISTERS.const(values).as_value().value
    return {name: (bits >> field.offset) & ((1 << field.width) - 1) for name, field in _REGISTERS}


def wire_registers(wire):
    """The sequencer record's fields (a struct view of :data:`SEQUENCER`) as the bits of a
    :class:`~gateware.dlpc410.params.Registers` value (high bits beyond each field dropped)."""
    from amaranth import Cat
    return Cat(wire[name][:field.width] for name, field in _REGISTERS)


def registers_bits(wire):
    """:func:`wire_registers` for the host and the models: the fields as ints -> the int value of
    the :class:`~gateware.dlpc410.params.Registers` the gateware hands on."""
    return sum((wire[name] & ((1 << field.width) - 1)) << field.offset for name, field in _REGISTERS)


def _any(terms):
    return _functools.reduce(_operator.or_, terms)


def register_faults(wire, row_cycles):
    """Why the sequencer could not obey a register set: ``{check: condition}``, each condition
    true when the set fails the check. ``wire`` maps the :data:`SEQUENCER` field names to ints
    (the host, the reference model) or to Amaranth values (the parser); the conditions are built
    with operators only, so both get the same checks. ``row_cycles``: the DMD's DCLK cycles per
    row, the shortest row period."""
    faults = {}
    for (name, field), (_, wire_width) in zip(_REGISTERS, SEQUENCER, strict=True):
        if wire_width > field.width:
            faults[f"{name}_fits"] = (wire[name] >> field.width) != 0
        if isinstance(field.shape, _enum.EnumMeta) and len(field.shape) < (1 << field.width):
            faults[f"{name}_known"] = _any([wire[name] == member.value for member in field.shape]) == 0
    faults["lsb_even_nonzero"] = (wire["lsb"] == 0) | ((wire["lsb"] & 1) != 0)
    faults["dark_gap_even"] = (wire["dark_gap"] & 1) != 0
    faults["stagger_even"] = (wire["stagger"] & 1) != 0
    faults["row_period"] = wire["row_period"] < row_cycles
    faults["period_nonzero"] = (wire["trigger"] == _TriggerMode.PERIODIC.value) & (wire["period"] == 0)
    return faults


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
