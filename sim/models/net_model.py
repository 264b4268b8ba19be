"""Reference model of the endpoint (network stack + application protocol), in plain Python.

It reads frames byte by byte with its own parsing and predicts, frame by frame, every counter,
every image row handed on, every configuration change and every reply. It is an oracle apart
from the gateware: only the application field tables are shared, as the protocol's single
definition; every rule that decides what a record does (the values refused, the power-up
configuration, frame id order) is written here from ``docs/protocol.md`` and the DMD's numbers
from :mod:`spec.facts`, not taken from the functions the parser is built from. Rows are
assembled from the image records' pixels as the page says (:class:`Rows`): a row goes on once
all of it has come in consecutive records of one frame.
"""

import math
from dataclasses import dataclass, field

from spec import facts, records, wire
from spec.records import RecordType

__all__ = ["Model", "Rows", "ones_sum", "sequencer_refusals", "newer", "REGISTER_LARGEST", "BROADCAST"]

BROADCAST = b"\xff" * 6
VLAN_TPIDS = (0x8100, 0x88A8, 0x9100)

#: The sequencer record's registers narrower than their bytes on the wire, with the largest value
#: each holds; every other register fills its bytes (the page: a value wider than its register
#: is refused).
REGISTER_LARGEST = {"reset_mode": 3, "order": 3, "trigger": 3, "anchor": 7, "chain": 1, "strict_rst": 1,
                    "source": 1, "ns_flip": 1, "park": 1, "trigger_hold": 1}
#: Register values the page's rules name: the global reset mode, the plane orders by
#: ``order_table`` and by group, the periodic trigger.
GLOBAL, BY_TABLE, BY_GROUP, PERIODIC = 0, 2, 3, 1
#: Pulse groups, their offsets' width and the entries of one plane order table (the page's
#: ``group_offsets`` and ``group_tables``).
GROUPS, OFFSET_BITS, PLANES = 16, 24, 8
#: The page's ``dmd`` clock, and the gated planes' times in its whole cycles: the mirrors settled
#: (pulse to motion, then the switching time) and the light source's fall.
DMD_HZ = 200e6
MIRRORS_SETTLED = math.ceil((facts.TIMING["t_pulse_to_mirror"].value + facts.TIMING["t_switch"].value) * DMD_HZ
                            - 1e-9)
LIGHT_FALL = math.ceil(facts.LIGHT["t_fall"].value * DMD_HZ - 1e-9)
#: The light times' entries are 24 bits each.
LIGHT_TIME_BITS = 24


def newer(frame, than):
    """Frame id order, as the page says: ``frame`` is newer than ``than`` when it is 1 to 32,767
    ahead of it, modulo 65,536."""
    return 1 <= (frame - than) % 65536 <= 32767


def sequencer_refusals(registers, dmd, beats=1):
    """Why the sequencer could not obey a register set (the record's fields as ints), each
    reason as the page lists it; empty for a set it takes. Written from the page alone, apart
    from the checks the parser is built from, so that a test can hold the two to agree."""
    r = registers
    row_cycle = dmd.dclk_per_row // beats       # the DMD's DCLK cycles per row over the beats
    clear = dmd.clear_row_cycles * row_cycle    # a block clear
    # a group of the reset mode: every block, 4, 2 or 1 (an unknown mode is refused anyway)
    group = min(dmd.blocks, {GLOBAL: dmd.blocks, 1: 4, 2: 2, 3: 1}.get(r["reset_mode"], 0))
    group_clears = group * (clear + clear % 2)  # each clear rounded up to even
    reload = r["t_rst"] + r["t_settle"] + max(0, group * dmd.rows_per_block - 1) * r["row_period"] + row_cycle
    dark_pulses = not r["chain"] or r["lsb"] < r["hide"]
    shortest = max(clear, 4)                    # a stagger or offset that is not 0
    lead = max(clear, row_cycle) + 2            # group 0's offset that is not 0, rounded up to even
    lead += lead % 2
    offsets = [r["group_offsets"] >> OFFSET_BITS * g & ((1 << OFFSET_BITS) - 1) for g in range(GROUPS)]

    def names_each_plane_once(tables, table):
        entries = {tables >> 3 * (PLANES * table + j) & 7 for j in range(PLANES)}
        return entries == set(range(PLANES))

    reasons = [f"{name} over {largest}" for name, largest in REGISTER_LARGEST.items() if r[name] > largest]
    checks = [
        ("lsb zero or odd", r["lsb"] == 0 or r["lsb"] % 2),
        ("dark_gap odd", r["dark_gap"] % 2),
        ("stagger odd", r["stagger"] % 2),
        ("a group's offset odd", any(offset % 2 for offset in offsets)),
        ("row_period under a row cycle", r["row_period"] < row_cycle),
        ("period shorter than lsb in periodic mode", r["trigger"] == PERIODIC and r["period"] < r["lsb"]),
        ("lsb shorter than t_rst + t_settle and the group's clears",
         r["lsb"] < r["t_rst"] + r["t_settle"] + group_clears),
        ("hide below the group's reload", r["hide"] < reload and r["hide"] <= r["lsb"] * 128 and r["lsb"] < reload),
        ("dark_gap below the group's reload where a dark pulse can come", dark_pulses and r["dark_gap"] < reload),
        ("t_settle under 3 cycles", r["t_settle"] < 3),
        ("a phased stagger not 0 but too short", r["reset_mode"] != GLOBAL and 0 < r["stagger"] < shortest),
        ("a group offset not 0 but too short", r["order"] == BY_GROUP
         and any(0 < offset < shortest for offset in offsets)),
        ("a group offset below group 0's", r["order"] == BY_GROUP and min(offsets) < offsets[0]),
        ("group 0's offset not 0 but under its lead", r["order"] == BY_GROUP and 0 < offsets[0] < lead),
        ("order_table not each plane once", r["order"] == BY_TABLE and not names_each_plane_once(r["order_table"], 0)),
        ("a group table not each plane once", r["order"] == BY_GROUP
         and not all(names_each_plane_once(r["group_tables"], g) for g in range(GROUPS))),
        ("gated_time odd", r["gated_time"] % 2),
    ]
    if r["gated_planes"]:
        gated_time, lead = r["gated_time"], r["light_lead"]
        light = [r["light_times"] >> LIGHT_TIME_BITS * e & ((1 << LIGHT_TIME_BITS) - 1) for e in range(PLANES)]
        checks += [
            ("some planes gated, not all", r["gated_planes"] != 255),
            ("gated in a phased reset mode", r["reset_mode"] != GLOBAL),
            ("gated_time shorter than t_rst + t_settle and the group's clears",
             gated_time < r["t_rst"] + r["t_settle"] + group_clears),
            ("gated_time below the group's reload where it hides the next plane",
             r["hide"] < reload and r["hide"] <= gated_time < reload),
            ("light_lead shorter than the mirrors' settle", lead < MIRRORS_SETTLED),
            ("a gated plane's light on at its next pulse", any(
                r["gated_planes"] >> e & 1 and lead + light[e] + LIGHT_FALL > gated_time for e in range(PLANES))),
        ]
    return reasons + [reason for reason, failed in checks if failed]


def ones_sum(raw):
    """RFC 1071 ones' complement sum of big-endian 16-bit words."""
    if len(raw) % 2:
        raw = raw + b"\0"
    total = sum(int.from_bytes(raw[i:i + 2], "big") for i in range(0, len(raw), 2))
    while total >> 16:
        total = (total & 0xFFFF) + (total >> 16)
    return total


@dataclass
class Model:
    dmd: object
    mac: int
    ip: int
    port: int
    frame_bits: int = 4
    beats: int = 1                  # DCLK beats per dmd cycle of the sequencer
    armed: int = 0                  # power-up arming: the build's (the endpoint's own is disarmed)
    counters: dict = field(default_factory=dict)
    rows: list = field(default_factory=list)        # (frame tag, row, bytes) handed on
    replies: list = field(default_factory=list)     # ("arp"|"icmp"|"status", details)
    config: dict = field(default_factory=dict)
    triggers: int = 0
    sequence_starts: int = 0                         # control records with the sequence-start action
    registers: list = field(default_factory=list)   # sequencer register sets passed on (wire dicts)
    entries: list = field(default_factory=list)     # sequence entry records passed on (wire dicts)
    _sequence: int | None = None

    def __post_init__(self):
        for name, _ in records.NET_COUNTERS + records.APP_COUNTERS:
            self.counters.setdefault(name, 0)
        self.counters.update(dmd_columns=self.dmd.columns, dmd_rows=self.dmd.rows)
        self.assembler = Rows(self.dmd)
        # the page's power-up configuration
        self.config = {"bit_depth": 8, "armed": int(self.armed), "sequence_length": 1, "entries": 0, "loop": 1,
                       "mac": int(self.mac), "ip": int(self.ip), "port": int(self.port)}

    def count(self, name, by=1):
        self.counters[name] += by

    # -- network ---------------------------------------------------------------------------

    def frame(self, raw, bad=False):
        """Feed one frame (destination MAC to end of payload); returns the drop cause or the
        kind of frame accepted."""
        raw = bytes(raw)
        self.count("frames")
        outcome = self._classify(raw, bad)
        if outcome.startswith("drop_"):
            self.count(outcome)
        else:
            self.count("accepted")
        return outcome

    def _classify(self, raw, bad):
        cfg = self.config
        mac, ip = cfg["mac"].to_bytes(6, "big"), cfg["ip"].to_bytes(4, "big")
        n = len(raw)
        if bad:
            return "drop_mac"
        if n < 14:
            return "drop_ethertype"
        if raw[0:6] not in (mac, BROADCAST):
            return "drop_dst_mac"
        ethertype = int.from_bytes(raw[12:14], "big")
        if ethertype in VLAN_TPIDS:
            return "drop_vlan"
        if ethertype == 0x0806:
            arp = raw[14:42]
            if (n < 42 or arp[0:2] != b"\0\1" or arp[2:4] != b"\x08\0" or arp[4] != 6 or arp[5] != 4
                    or arp[6:8] != b"\0\1" or arp[24:28] != ip):
                return "drop_arp"
            self.count("arp_replies")
            self.replies.append(("arp", {"mac": arp[8:14], "ip": arp[14:18]}))
            return "arp"
        if ethertype != 0x0800:
            return "drop_ethertype"
        head = raw[14:34]
        total = int.from_bytes(head[2:4], "big") if n >= 18 else 0
        end = 14 + total
        if n < 34 or total < 20 or n < end:
            return "drop_ip_length"
        if head[0] >> 4 != 4:
            return "drop_ip_version"
        if head[0] & 15 != 5:
            return "drop_ip_options"
        if ones_sum(head) != 0xFFFF:
            return "drop_ip_checksum"
        if head[6] & 0x20 or int.from_bytes(head[6:8], "big") & 0x1FFF:
            return "drop_ip_fragment"
        if head[16:20] != ip:
            return "drop_ip_dst"
        payload = raw[34:end]
        if head[9] == 1:
            if len(payload) < 8 or payload[0] != 8 or payload[1] != 0 or ones_sum(payload) != 0xFFFF:
                return "drop_icmp"
            self.count("icmp_replies")
            self.replies.append(("icmp", {"mac": raw[6:12], "ip": head[12:16], "message": payload}))
            return "icmp"
        if head[9] != 17:
            return "drop_ip_protocol"
        udp_length = int.from_bytes(raw[38:40], "big")
        if udp_length <= 8 or udp_length != len(payload):
            return "drop_udp_length"
        if int.from_bytes(raw[36:38], "big") != cfg["port"]:
            return "drop_udp_port"
        pseudo = head[12:20] + bytes([0, 17]) + udp_length.to_bytes(2, "big")
        if raw[40:42] != b"\0\0" and ones_sum(pseudo + payload) != 0xFFFF:
            return "drop_udp_checksum"
        peer = {"mac": raw[6:12], "ip": head[12:16], "port": int.from_bytes(raw[34:36], "big")}
        self.record(payload[8:], peer)
        return "udp"

    # -- application -----------------------------------------------------------------------

    def record(self, data, peer=None):
        """Feed one datagram's payload; returns the drop cause or the record type accepted."""
        outcome = self._record(bytes(data), peer)
        if outcome.startswith("drop_"):
            self.count(outcome)
        return outcome

    def _record(self, data, peer):
        header_size = wire.size(records.HEADER)
        sizes = {RecordType.IMAGE: records.IMAGE_HEADER,
                 RecordType.DELTA: records.DELTA_HEADER,
                 RecordType.CONTROL: header_size + wire.size(records.CONTROL),
                 RecordType.SEQUENCER: header_size + wire.size(records.SEQUENCER),
                 RecordType.ENTRY: header_size + wire.size(records.ENTRY),
                 RecordType.STATUS_QUERY: header_size}
        padded = data + bytes(max(0, max(sizes.values()) - len(data)))
        head = wire.unpack(records.HEADER, padded)
        kind = head["type"]
        if head["magic"] != records.MAGIC:
            return "drop_app_magic"
        if head["version"] != records.VERSION:
            return "drop_app_version"
        if kind not in sizes:
            return "drop_app_type"
        if len(data) < sizes[kind]:
            return "drop_app_length"
        has_pixels = kind in (RecordType.IMAGE, RecordType.DELTA)
        if has_pixels and len(data) == sizes[kind]:
            return "drop_app_empty"
        if not has_pixels and len(data) != sizes[kind]:
            return "drop_app_length"
        if has_pixels:
            image = wire.unpack(records.IMAGE if kind == RecordType.IMAGE else records.DELTA,
                                data[header_size:])
            pixels = data[sizes[kind]:]
            if image["offset"] + len(pixels) > self.dmd.rows * self.dmd.columns:
                return "drop_app_rows"
            # (the protocol page's rule: a delta carries at least one row)
            if kind == RecordType.DELTA and image["carried"] == 0:
                return "drop_app_value"
        if kind == RecordType.CONTROL:
            control = wire.unpack(records.CONTROL, data[header_size:])
            names = [name for name, _ in records.CONFIG]
            # every whole 8-bit frame the memory holds, 256 at most
            frames = min(256, int(facts.MEMORY["bytes"].value) // (self.dmd.rows * self.dmd.columns))

            def applies(name):
                return control["apply"] >> names.index(name) & 1
            if ((applies("bit_depth") and not 1 <= control["bit_depth"] <= 8)
                    or (applies("armed") and control["armed"] > 1)
                    or (applies("sequence_length") and not 1 <= control["sequence_length"] <= frames)
                    or (applies("entries") and control["entries"] > 2048)
                    or (applies("loop") and control["loop"] > 1)):
                return "drop_app_value"
        if kind == RecordType.ENTRY:
            # (the protocol page's rules, written out here, not the parser's shared function)
            entry = wire.unpack(records.ENTRY, data[header_size:])
            if (entry["index"] > 2047 or entry["slot"] >= self.config["sequence_length"] or entry["lsb"] % 2
                    or entry["dark"] % 2 or entry["follow"] > 1 or entry["camera_off"] > 1
                    or entry["depth"] > 8 or entry["skip"] > 7):
                return "drop_app_value"
        if kind == RecordType.SEQUENCER:
            registers = wire.unpack(records.SEQUENCER, data[header_size:])
            if sequencer_refusals(registers, self.dmd, self.beats):
                return "drop_app_value"
        mask = (1 << dict(records.HEADER)["sequence"]) - 1
        if self._sequence is not None and head["sequence"] != (self._sequence + 1) & mask:
            self.count("sequence_gaps")
        self._sequence = head["sequence"]
        if has_pixels:
            self.count("records_image")
            tag = (1 << self.frame_bits) - 1
            for frame, row, row_bytes in self.assembler.record(image["frame"], image["offset"], pixels):
                self.rows.append((frame & tag, row, row_bytes))
            self.counters.update(self.assembler.counters)
            return "image"
        if kind == RecordType.CONTROL:
            for i, (name, _) in enumerate(records.CONFIG):
                if control["apply"] >> i & 1:
                    self.config[name] = control[name]
            self.triggers += control["action"] & 1
            self.sequence_starts += control["action"] >> 1 & 1
            self.count("records_control")
            return "control"
        if kind == RecordType.ENTRY:
            self.entries.append(entry)
            self.count("records_entry")
            return "entry"
        if kind == RecordType.SEQUENCER:
            self.registers.append(registers)
            self.count("records_sequencer")
            return "sequencer"
        self.count("records_status")
        self.replies.append(("status", {**(peer or {}), "sequence": head["sequence"]}))
        return "status"


class Rows:
    """Whole rows from image records' pixels, as ``docs/protocol.md`` says.

    A record continues the row waiting for it when it is of the same frame and starts where the
    previous record ended; otherwise that row is abandoned, and so are the record's own pixels
    before its first row start (each an incomplete row). Rows are handed on whole, in order."""

    def __init__(self, dmd):
        self.columns = dmd.columns
        self.waiting = None          # (frame, next position, bytes of the row so far)
        self.counters = {name: 0 for name, _ in records.ROW_COUNTERS}
        self._seen = False

    def record(self, frame, offset, pixels):
        """One image record's pixels; returns the rows it completes: ``[(frame id, row, bytes)]``."""
        columns = self.columns
        if self.waiting is not None and self.waiting[:2] == (frame, offset):
            data = self.waiting[2] + pixels
            start = offset - len(self.waiting[2])
        else:
            self.counters["rows_incomplete"] += (self.waiting is not None) + (offset % columns != 0)
            skip = -offset % columns
            data, start = pixels[skip:], offset + skip
        whole = len(data) // columns * columns
        out = [(frame, (start + at) // columns, data[at:at + columns]) for at in range(0, whole, columns)]
        self.waiting = (frame, start + len(data), data[whole:]) if len(data) > whole else None
        for frame_id, row, row_bytes in out:
            self._handed_on(frame_id, row, len(row_bytes))
        return out

    def _handed_on(self, frame, row, size):
        c = self.counters
        c["rows"] += 1
        c["payload_bytes"] += size
        c["last_frame"], c["last_row"] = frame, row
        if not self._seen or newer(frame, c["newest_frame"]):
            c["newest_frame"] = frame
        self._seen = True
