"""The application protocol's records: the one definition both ends speak.

Every record is a sequence of big-endian fields. Each table below lists ``(name, width in bits)``
in wire order (:mod:`spec.wire` packs and unpacks them). The gateware's parser and status reply
are built from these tables (:mod:`gateware.wire` gives their Amaranth views), and so are the
host's encoder and decoder (:mod:`host.codec`); ``docs/protocol.md`` describes the meaning of
each field, the widths live only here. Plain Python: the host needs no HDL toolchain.

One authority per setting: the sequencer's run-time registers (:data:`spec.registers.FIELDS`:
trigger mode, plane durations, reset mode, ...) are set only by the sequencer record
(:data:`SEQUENCER`, derived from that table, so that a register added there is on the wire with
no edit here); the control record (:data:`CONFIG`) sets what the rest of the projector uses: the
store's bit depth and sequence, arming, the network addresses.
"""

__all__ = [
    "MAGIC", "VERSION", "RecordType", "Action", "ENTRIES",
    "HEADER", "IMAGE", "DELTA", "CONTROL", "CONFIG", "SEQUENCER", "ENTRY", "entry_faults", "delta_faults",
    "config_faults", "sequence_frames",
    "NET_COUNTERS", "RECORD_COUNTERS",
    "ROW_COUNTERS", "GEOMETRY", "APP_COUNTERS", "SYSTEM_STATUS", "STATUS_REPLY", "IMAGE_HEADER",
    "DELTA_HEADER",
    "MASTER_CONFIG", "MASTER_CONTROL", "MASTER_RECORD_COUNTERS", "MASTER_STATUS", "MASTER_STATUS_REPLY",
    "master_config_faults",
    "MAX_RECORD", "UDP_IP_OVERHEAD", "record_limit", "frame_newer",
    "register_wire", "registers_bits", "register_faults", "group_reload",
]

import enum as _enum
import functools as _functools
import operator as _operator

from . import facts
from . import registers as _registers
from .schedule.terms import LIGHT_FALL as _LIGHT_FALL
from .schedule.terms import MIRRORS_SETTLED as _MIRRORS_SETTLED
from .wire import size

#: ``"DM"``: first two bytes of every record.
MAGIC = 0x444D
#: Protocol version this tree speaks; records with any other version are dropped and counted.
#: ``magic`` and ``version`` keep their places in every version, so that a projector can tell.
VERSION = 11
#: IPv4 and UDP headers around a record: a record fills an MTU less these.
UDP_IP_OVERHEAD = 28
#: Largest record: a UDP payload inside a 9000-byte IP MTU (9000 - 20 IPv4 - 8 UDP).
MAX_RECORD = 9000 - UDP_IP_OVERHEAD


class RecordType(_enum.IntEnum):
    IMAGE = 1
    CONTROL = 2
    STATUS_QUERY = 3
    STATUS_REPLY = 4
    SEQUENCER = 5
    ENTRY = 6
    DELTA = 7
    MASTER_CONTROL = 8   # to a sync master: its settings, a software trigger
    MASTER_STATUS = 9    # a sync master's answer to a status query


class Action(_enum.IntFlag):
    SOFTWARE_TRIGGER = 1
    SEQUENCE_START = 2       # play the sequence's entries from the first


#: Entries a sequence's table holds (entry records' ``index`` below it).
ENTRIES = 2048


#: Common header of every record. A record is a whole UDP payload: its length is the datagram's.
HEADER = [
    ("magic", 16),
    ("version", 8),
    ("type", 8),
    ("sequence", 8),     # sender's record counter (mod 256); gaps are counted as loss
]

#: Image record body (after :data:`HEADER`), followed by its pixel bytes: the rest of the
#: datagram, consecutive pixels of a whole frame (row by row, left to right) from ``offset``.
IMAGE = [
    ("frame", 16),       # frame id (serial-number order: see frame_newer)
    ("offset", 24),      # position of the first pixel carried: row * columns + column
]

#: Delta record body (after :data:`HEADER`), followed by its pixel bytes as an image record's.
#: A delta frame carries only the rows that differ from ``base``, a whole frame the projector
#: holds; it takes every other row, and its bit depth, from that frame. Every record of one
#: frame has the same ``base`` and ``carried``. A record type of its own, so that a whole
#: frame's records do not carry these four bytes (a 1,500-byte MTU's record keeps 1,462 pixels).
DELTA = [
    ("frame", 16),       # frame id (serial-number order: see frame_newer)
    ("base", 16),        # the whole frame whose rows it keeps where it carries none
    ("carried", 16),     # how many distinct rows it carries (1..rows)
    ("offset", 24),      # position of the first pixel carried: row * columns + column
]

#: Run-time configuration: the registers a control record sets (the gateware's ``Config``).
CONFIG = [
    ("bit_depth", 8),        # 1..8 planes stored per frame
    ("armed", 8),            # 1: triggers reach the sequencer; 0: every trigger source is ignored
    ("sequence_length", 16), # frame slots in the sequence (1 = a single frame, streamed)
    ("entries", 16),         # entries of the sequence's table played (0: its slots in order)
    ("loop", 8),             # 1: the entries play in a loop; 0: once, then triggers are ignored
    ("mac", 48),             # our MAC address
    ("ip", 32),              # our IPv4 address
    ("port", 16),            # our UDP port
]

#: Control record body: ``apply`` bit i makes CONFIG field i take the record's value; the others
#: keep theirs. ``action`` bits are one-shot commands (:class:`Action`).
CONTROL = [("apply", 16), ("action", 8)] + CONFIG

#: Sequencer record body: every register of :data:`spec.registers.FIELDS`, in that order, each
#: widened to whole bytes (the high bits must be zero). An enum field carries its value;
#: ``order_table`` carries entry ``j`` in bits ``3j..3j+2``.
SEQUENCER = [(f.name, -(-f.bits // 8) * 8) for f in _registers.FIELDS]

#: Sequence entry record body: entry ``index`` of the sequence's table shows the frame of slot
#: ``slot`` with a least significant plane of ``lsb`` cycles (0: the sequencer register's), at
#: least ``dark`` cycles dark after it before a frame that follows it, and it ``follow``s the
#: frame before it with no trigger (1) or waits for one (0); ``camera_off`` 1: no camera trigger.
#: It shows ``depth`` of its frame's planes (0: all of them) after leaving out the ``skip`` most
#: significant ones, as a ``depth``-bit image.
ENTRY = [
    ("index", 16),
    ("slot", 8),
    ("lsb", 24),
    ("dark", 24),
    ("follow", 8),
    ("camera_off", 8),
    ("depth", 8),
    ("skip", 8),
]

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
RECORD_COUNTERS = [
    ("records_image", 32),     # image and delta records
    ("records_control", 32),   # control records applied
    ("records_sequencer", 32), # sequencer records passed on (applied when the sequencer rests)
    ("records_status", 32),
    ("drop_app_magic", 32),    # not a record of this protocol
    ("drop_app_version", 32),
    ("drop_app_type", 32),
    ("drop_app_empty", 32),    # an image or delta record without pixels
    ("drop_app_length", 32),   # the datagram shorter than its type's header, or not its type's size
    ("drop_app_rows", 32),     # pixels beyond the frame
    ("drop_app_value", 32),    # a control, sequencer, entry record with a value it cannot obey; a delta of no rows
    ("records_entry", 32),     # sequence entry records written to the table
    ("sequence_gaps", 32),     # records whose sequence number was not the previous + 1
]

#: Counters kept by the row assembler (whole rows handed to the bit-plane serialiser).
ROW_COUNTERS = [
    ("rows", 32),              # image rows handed on
    ("rows_incomplete", 32),   # rows begun and abandoned: a piece of them was lost or came out of order
    ("payload_bytes", 48),     # pixel bytes handed on
    ("last_frame", 16),        # frame id and row of the last row handed on
    ("last_row", 16),
    ("newest_frame", 16),      # newest frame id handed on (serial-number order): continue after it
]

#: The DMD's geometry, as the projector was built for it (image records' positions count in it).
GEOMETRY = [
    ("dmd_columns", 16),
    ("dmd_rows", 16),
]

#: The application's part of the status reply.
APP_COUNTERS = RECORD_COUNTERS + ROW_COUNTERS + GEOMETRY

#: Figures the rest of the system supplies (the gateware's ``Status`` input).
SYSTEM_STATUS = [
    ("uptime_cycles", 48),     # system clock cycles since reset
    ("clock_hz", 32),
    ("triggers", 32),          # triggers obeyed
    ("trigger_overruns", 32),  # triggers that came while a frame was still showing
    ("frames_shown", 32),
    ("shown_frame", 16),       # frame id of the frame shown last (its first clocking pulse)
    ("dlpc410_state", 16),     # bits: 0 INIT_ACTIVE, 1 RST_ACTIVE, 2 ECP2_FINISHED, 3 DDR2 calibrated, 4-6 link
    ("triggers_early", 32),    # triggers before the DLPC410 finished initialising
    ("pulses_late", 32),       # clocking pulses made after their time
    ("row_underruns", 32),     # row loads that waited for the store
    ("frames_bad_depth", 32),  # frames offered with a bit depth outside 1..8 or their order cannot show
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
    ("store_rows_refused", 32),      # rows the store refused (outside, stale, shown, duplicate, no slot, no base)
    ("triggers_held", 32),     # triggers that came too early, held and obeyed once every group was ready
    ("rst_active_late", 32),   # RST_ACTIVE fell later than planned: the settle counted from its fall
    ("rst_active_faults", 32), # RST_ACTIVE did not rise after a pulse, or stayed high far too long
    ("dlpc410_restarts", 32),  # the DLPC410 initialised again mid-run (INIT_ACTIVE high again, ECP2_FINISHED low)
    ("store_calibration_losses", 32),  # the DDR2 lost its calibration: every stored frame forgotten
    ("store_frames_lost", 32),         # frames forgotten (stored, arriving or held) when the DDR2 was lost
    ("rst_active_cycles_max", 32),     # the longest RST_ACTIVE seen, in dmd cycles from a pulse: the t_rst to plan with
    ("frames_period_short", 32),       # frames the periodic trigger started whose planes outlast its period
    ("store_rows_no_base", 32),        # rows of a delta refused: its base is not a whole frame the store holds
    ("triggers_after_end", 32),        # triggers ignored: a sequence played once had ended
    ("sequence_entries_skipped", 32),  # sequence entries skipped: their slot is outside the sequence,
                                       # or their planes outside their frame
    ("clock_loop_slips", 32),          # sync pulses far from where the board's clock loop expected them
    ("clock_loop_locked", 8),          # 1 while the clock loop holds the board's clock to the sync master's
]

#: Status reply body (after :data:`HEADER`).
STATUS_REPLY = NET_COUNTERS + APP_COUNTERS + SYSTEM_STATUS


#: The sync master's run-time configuration (a master control record sets it; times in the
#: master's ``sync`` cycles, :data:`MASTER_STATUS`'s ``clock_hz``).
MASTER_CONFIG = [
    ("mode", 8),             # what starts a frame (spec.registers.TriggerMode, SYNC excepted)
    ("armed", 8),            # 1: triggers are obeyed; 0: every trigger is ignored
    ("period", -(-_registers.DURATION_BITS // 8) * 8),      # the periodic trigger's period
    ("min_period", -(-_registers.DURATION_BITS // 8) * 8),  # a trigger sooner after a pulse is refused
    ("width", 16),           # each sync and camera pulse's length
]

#: Master control record body: ``apply`` bit i makes MASTER_CONFIG field i take the record's
#: value; ``action`` (:class:`Action`): SOFTWARE_TRIGGER, after the fields are set.
MASTER_CONTROL = [("apply", 8), ("action", 8)] + MASTER_CONFIG

#: The records a sync master keeps count of: those of :data:`RECORD_COUNTERS` that it can see.
MASTER_RECORD_COUNTERS = [(name, width) for name, width in RECORD_COUNTERS
                          if name in ("records_control", "records_status", "drop_app_magic", "drop_app_version",
                                      "drop_app_type", "drop_app_length", "drop_app_value", "sequence_gaps")]

#: What a sync master reports besides its network counters: its pulses and refusals, its
#: boards' ready lines, the configuration in force, its MAC's verdicts.
MASTER_STATUS = [
    ("uptime_cycles", 48),   # sync cycles since reset
    ("clock_hz", 32),        # the sync clock: the unit of every time in MASTER_CONFIG
    ("boards", 8),           # sync outputs the master was built with
    ("ready", 16),           # the boards' ready lines now (bit k: board k)
    ("pulses", 32),          # sync pulses sent (one per frame, on every board's line)
    ("not_ready", 32),       # triggers refused: a board was not ready
    ("early", 32),           # triggers refused: sooner than min_period after the last pulse
    *MASTER_CONFIG,
    *[(name, width) for name, width in SYSTEM_STATUS if name.startswith("mac_")],
]

#: Master status reply body (after :data:`HEADER`).
MASTER_STATUS_REPLY = NET_COUNTERS + MASTER_RECORD_COUNTERS + MASTER_STATUS


def master_config_faults(config):
    """Why a sync master cannot take a configuration (``{check: condition}``, as
    :func:`register_faults`): ``config`` maps :data:`MASTER_CONFIG`'s names to the values the
    record would leave in force (its own where it applies them, the others as they are). A
    master has no sync input to obey (mode SYNC); each pulse ends before the next may start."""
    modes = [m.value for m in _registers.TriggerMode if m != _registers.TriggerMode.SYNC]
    return {
        "mode": _any([config["mode"] == mode for mode in modes]) == 0,
        "armed": config["armed"] > 1,
        "width": config["width"] == 0,
        "width_below_min_period": config["width"] >= config["min_period"],
        "period_keepable": ((config["mode"] == _registers.TriggerMode.PERIODIC.value)
                            & (config["period"] < config["min_period"])),
    }



def register_wire(values):
    """Register values (a dict of ints, enum members and the ``order_table`` list) -> the
    sequencer record's field values (ints)."""
    bits = _registers.pack(values)
    return {name: (bits >> offset) & ((1 << width) - 1)
            for name, (offset, width) in _registers.layout_bits().items()}


def registers_bits(wire):
    """The sequencer record's fields as ints -> the packed register set (an int) the gateware
    hands on: each field's bits beyond the register's width are dropped."""
    return sum((wire[name] & ((1 << width) - 1)) << offset
               for name, (offset, width) in _registers.layout_bits().items())


def _any(terms):
    return _functools.reduce(_operator.or_, terms)


def register_faults(wire, dmd, beats=1, *, reload_terms=None):
    """Why the sequencer could not obey a register set: ``{check: condition}``, each condition
    true when the set fails the check. ``wire`` maps the :data:`SEQUENCER` field names to ints
    (the host, the reference model) or to Amaranth values (the parser); the conditions are built
    with operators only, so both get the same checks. ``dmd``: the :class:`spec.facts.DmdType`
    played; ``beats``: its DCLK beats per cycle of the sequencer (a row cycle, the shortest row
    period, is the DMD's DCLK cycles per row over the beats). ``reload_terms``: the
    :func:`group_reload` of ``wire`` worked out before (the parser registers it a cycle ahead of
    the checks, so that no path holds both the product and the comparisons), else worked out here.

    What a group of the reset mode needs between two of its pulses (:func:`group_reload`): its
    reset and settle time (``t_rst + t_settle``), then its blocks cleared (to end a plane with a
    dark pulse) or its rows loaded at the row period (to show the next plane). Each check below
    refuses a set in which some group would need more than it is given:

    ``lsb_keepable``: the least significant plane holds the group's clears (a dark pulse ends it,
    the shortest way to end a plane: ``docs/bounds.md``);

    ``hide_keepable``: a plane at least ``hide`` long has the next plane loaded behind it, so
    hiding must start no shorter than the reload; a ``hide`` below the reload is kept only when
    no plane is as long as ``hide`` or the least significant plane already holds the reload;

    ``dark_gap_keepable``: after a dark pulse the next plane is loaded, so the gap holds the
    reload, whenever a dark pulse can come (not chained, or a plane shorter than ``hide``).

    These are what one group needs on its own to show full frames. In the global mode (one
    group) they are all it needs: a set that passes plays on time (``tests/test_register_rule.py``
    holds that against the schedule model). In a phased mode the groups' loads share the bus,
    and a set that passes can still make a pulse late (counted in ``pulses_late``); the plan
    finder's plans are checked against that by the schedule model. The one check stricter than
    need be is ``hide_keepable``: a ``hide`` below the reload that no plane's length falls
    between is refused, though every plane it makes hide could (``sim.bench.registers_figures``
    counts such refusals).

    ``period_keepable``: a periodic trigger's period is at least the least significant plane, the
    shortest a frame (one plane) can last; frames of more planes that outlast it are counted
    when they start (``frames_period_short``).

    ``settle_keepable``: the sequencer's settle countdown starts when its RST_ACTIVE countdown
    ends, so it keeps settle times of :data:`spec.registers.MIN_SETTLE` cycles or more exactly.

    ``stagger_keepable``: in a phased mode each group's first pulse is timed from the one before
    it, so groups a stagger apart keep their times exactly when the stagger is 0 or at least a
    block clear's row cycles (no load of a clear's length fits between two first pulses), and
    :data:`spec.registers.MIN_CHAINED` (the notice a timed first pulse needs);
    ``group_offsets_keepable``: likewise each group's offset of :attr:`PlaneOrder.GROUPS
    <spec.registers.PlaneOrder.GROUPS>` (each is timed from the first pulses a trigger times at
    once, group 0's included; group 0's, if not 0, :func:`spec.registers.lead_cycles` at least),
    and no group's is below group 0's: its first pulse starts the frame (the trigger's latency,
    the camera, ``sync_out``). Group 0's offset leaves the bus time to end an operation under
    way when the trigger comes (in GROUPS, once frames follow triggers, other groups' first loads
    may still run then: :mod:`spec.schedule`).

    ``order_table_permutation``, ``group_tables_permutation``: in :attr:`PlaneOrder.TABLE
    <spec.registers.PlaneOrder.TABLE>` the order table, in :attr:`PlaneOrder.GROUPS
    <spec.registers.PlaneOrder.GROUPS>` every one of the group tables (used by the reset mode or
    not), names each weight exponent 0..7 once: a table that repeats a plane would show wrong
    levels. A frame of fewer planes plays only if the first entries of each table in force name
    its planes (the sequencer drops any other, and counts it).

    Gated planes (``gated_planes`` not 0: the gate pin switches the light source, one source for
    the whole DMD): ``gated_planes_whole``, every plane of a frame is gated or none (a plane lit
    through its mirrors' transitions beside one lit only while they rest would be off by part of
    a transition: the mask is 0 or 255); ``gated_global``, only in the global reset mode (phased
    groups show different planes at once); ``gated_time_even``; ``gated_time_keepable``, a gated
    plane is held to what a plane of its length needs, as the least significant plane is (its
    group's clears behind the settle, and the ``hide`` rule); ``light_lead_keepable``, the light
    comes no sooner than the mirrors settle (:data:`spec.schedule.MIRRORS_SETTLED` cycles after
    the pulse); ``light_times_keepable``, each gated plane's light is off, the source's fall
    (:data:`spec.schedule.LIGHT_FALL`) included, by the next pulse: ``light_lead +
    light_times[e] + fall <= gated_time``."""
    row_cycles, clear_row_cycles = _row_cycles(dmd, beats), dmd.clear_row_cycles
    faults = {}
    for f, (_, wire_width) in zip(_registers.FIELDS, SEQUENCER, strict=True):
        if wire_width > f.bits:
            faults[f"{f.name}_fits"] = (wire[f.name] >> f.bits) != 0
        if f.enum is not None and len(f.enum) < (1 << f.width):
            faults[f"{f.name}_known"] = _any([wire[f.name] == member.value for member in f.enum]) == 0
    faults["lsb_even_nonzero"] = (wire["lsb"] == 0) | ((wire["lsb"] & 1) != 0)
    faults["dark_gap_even"] = (wire["dark_gap"] & 1) != 0
    faults["stagger_even"] = (wire["stagger"] & 1) != 0
    faults["row_period"] = wire["row_period"] < row_cycles
    settle = wire["t_rst"] + wire["t_settle"]
    clears, reload = reload_terms if reload_terms is not None else group_reload(wire, dmd, beats)
    faults["lsb_keepable"] = wire["lsb"] < settle + clears
    faults["hide_keepable"] = ((wire["hide"] < reload) & (wire["hide"] <= (wire["lsb"] << 7))
                               & (wire["lsb"] < reload))
    faults["dark_gap_keepable"] = (((wire["chain"] == 0) | (wire["lsb"] < wire["hide"]))
                                   & (wire["dark_gap"] < reload))
    faults["period_keepable"] = ((wire["trigger"] == _registers.TriggerMode.PERIODIC.value)
                                 & (wire["period"] < wire["lsb"]))
    faults["settle_keepable"] = wire["t_settle"] < _registers.MIN_SETTLE
    width = next(f.width for f in _registers.FIELDS if f.name == "group_offsets")
    offsets = [_bits(wire["group_offsets"], width * g, width) for g in range(_registers.MAX_GROUPS)]
    faults["group_offsets_even"] = _any([(o & 1) != 0 for o in offsets])
    least = max(clear_row_cycles * row_cycles, _registers.MIN_CHAINED)
    # (group 0's, not 0, lets a trigger come while loads run)
    lead = _registers.lead_cycles(row_cycles, clear_row_cycles)
    faults["group_offsets_keepable"] = ((wire["order"] == _registers.PlaneOrder.GROUPS.value)
                                        & (_any([(o != 0) & (o < least) for o in offsets])
                                           | ((offsets[0] != 0) & (offsets[0] < lead))
                                           | _any([o < offsets[0] for o in offsets[1:]])))
    faults["stagger_keepable"] = ((wire["reset_mode"] != _registers.ResetMode.GLOBAL.value) & (wire["stagger"] != 0)
                                  & (wire["stagger"] < least))
    faults["order_table_permutation"] = ((wire["order"] == _registers.PlaneOrder.TABLE.value)
                                         & (_permutation(wire["order_table"], 0) == 0))
    faults["group_tables_permutation"] = ((wire["order"] == _registers.PlaneOrder.GROUPS.value)
                                          & (_all([_permutation(wire["group_tables"], g)
                                                    for g in range(_registers.MAX_GROUPS)]) == 0))
    _gated_faults(faults, wire, settle + clears, reload)
    return faults


def _gated_faults(faults, wire, shortest, reload):
    """:func:`register_faults`'s checks of gated planes, with ``shortest`` (a plane ended by a
    dark pulse: the settle and the group's clears) and ``reload`` (the group's) worked out."""
    mask, time, lead = wire["gated_planes"], wire["gated_time"], wire["light_lead"]
    gated = mask != 0
    faults["gated_planes_whole"] = gated & (mask != 0xFF)
    faults["gated_global"] = gated & (wire["reset_mode"] != _registers.ResetMode.GLOBAL.value)
    faults["gated_time_even"] = (time & 1) != 0
    faults["gated_time_keepable"] = gated & ((time < shortest)
                                             | ((wire["hide"] < reload) & (wire["hide"] <= time) & (time < reload)))
    faults["light_lead_keepable"] = gated & (lead < _MIRRORS_SETTLED)
    width = next(f.width for f in _registers.FIELDS if f.name == "light_times")
    faults["light_times_keepable"] = _any([(_bits(mask, e, 1) != 0)
                                           & (lead + _bits(wire["light_times"], width * e, width) + _LIGHT_FALL > time)
                                           for e in range(8)])


def group_reload(wire, dmd, beats=1):
    """(clears, reload) of the largest group of ``wire``'s reset mode: the cycles its blocks'
    clears take on the bus, and from a pulse to the earliest next pulse when the group is loaded
    in between (``t_rst + t_settle``, then its rows at ``row_period``, the last a row cycle
    long). Operators only, as :func:`register_faults`; an unknown mode gives 0 (it is refused)."""
    mode, row_cycles = wire["reset_mode"], _row_cycles(dmd, beats)
    clear = _registers.clear_cycles(row_cycles, dmd.clear_row_cycles)
    sizes = {m: _registers.group_blocks(m, dmd.blocks) for m in _registers.ResetMode}
    clears = sum((mode == m.value) * (size * clear) for m, size in sizes.items())
    rows_after_first = sum((mode == m.value) * (size * dmd.rows_per_block - 1) for m, size in sizes.items())
    return clears, wire["t_rst"] + wire["t_settle"] + rows_after_first * wire["row_period"] + row_cycles


def _row_cycles(dmd, beats):
    """A row cycle in the sequencer's cycles: the DMD's DCLK cycles per row over the beats."""
    assert dmd.dclk_per_row % beats == 0
    return dmd.dclk_per_row // beats


def _permutation(tables, t):
    """Whether table ``t`` of the packed order tables ``tables`` (eight 3-bit exponents each)
    names every exponent 0..7 once: its eight entries differ pairwise."""
    exps = [_bits(tables, 3 * (8 * t + j), 3) for j in range(8)]
    return _all([exps[i] != exps[j] for i in range(8) for j in range(i)])


def _bits(value, offset, width):
    """``width`` bits of ``value`` (an int, or an Amaranth value: sliced, so that no logic as
    wide as the whole value is formed) from bit ``offset``."""
    try:
        return (_operator.index(value) >> offset) & ((1 << width) - 1)
    except TypeError:
        return value[offset:offset + width]


def _all(terms):
    return _functools.reduce(_operator.and_, terms)


def delta_faults(wire):
    """Why a delta record cannot be taken (``{check: condition}``, as :func:`register_faults`):
    it carries no rows (a whole frame goes as image records). A count beyond the frame's rows is
    the store's to refuse with the frame's rows (``store_rows_refused``)."""
    return {"carried": wire["carried"] == 0}


def entry_faults(wire, sequence_length):
    """Why an entry record cannot be written (``{check: condition}``, as
    :func:`register_faults`): its index beyond the table, a slot outside the sequence in force
    (``sequence_length``), an odd time, a flag other than 0 or 1, a bit depth over 8, more than
    7 planes left out (whether its planes are in its frame is known only when it plays)."""
    return {
        "index": wire["index"] >= ENTRIES,
        "slot": wire["slot"] >= sequence_length,
        "lsb_even": (wire["lsb"] & 1) != 0,
        "dark_even": (wire["dark"] & 1) != 0,
        "follow": wire["follow"] > 1,
        "camera_off": wire["camera_off"] > 1,
        "depth": wire["depth"] > 8,
        "skip": wire["skip"] > 7,
    }


def sequence_frames(rows, columns):
    """The most frames a stored sequence holds on a DMD of ``rows`` x ``columns`` (on the bus):
    every whole frame in the store's memory, up to the slots an entry record names (DLP7000 170,
    DLP9500 60)."""
    return min(1 << dict(ENTRY)["slot"], facts.frames_held(rows, columns))


def config_faults(wire, applies, frames):
    """Why a control record cannot be applied (``{check: condition}``): a field it applies
    (``applies(name)`` true) holds a value nothing obeys (a sequence longer than the ``frames``
    the projector holds, :func:`sequence_frames`, included)."""
    return {
        "bit_depth": applies("bit_depth") & ((wire["bit_depth"] == 0) | (wire["bit_depth"] > 8)),
        "armed": applies("armed") & (wire["armed"] > 1),
        "sequence_length": applies("sequence_length") & ((wire["sequence_length"] == 0)
                                                         | (wire["sequence_length"] > frames)),
        "entries": applies("entries") & (wire["entries"] > ENTRIES),
        "loop": applies("loop") & (wire["loop"] > 1),
    }


#: Bytes of an image record before its pixels.
IMAGE_HEADER = size(HEADER) + size(IMAGE)
#: Bytes of a delta record before its pixels.
DELTA_HEADER = size(HEADER) + size(DELTA)


def record_limit(mtu):
    """Largest record that travels unfragmented in an IP MTU of ``mtu`` bytes."""
    return min(mtu, 9000) - UDP_IP_OVERHEAD


def frame_newer(frame, than):
    """Frame ids are ordered as serial numbers (RFC 1982, 16 bits): ``frame`` is newer than
    ``than`` when it is 1 to 32,767 ahead of it, modulo 65,536."""
    return 0 < (frame - than) % (1 << 16) < (1 << 15)
