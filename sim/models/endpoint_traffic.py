"""Test traffic for the endpoint (stack + protocol) on the test geometry.

Every class of bad input with the counter that must count it (:data:`BAD_CASES`: the stack's bad
frames, a bad MAC verdict, malformed records and register sets the sequencer could not obey), and
:func:`randomized_mix`, hundreds of frames of every kind interleaved. Frames are built by scapy and
the host encoder; what the endpoint must make of them comes from the reference model
(:class:`sim.models.net_model.Model`). Shared by the Amaranth-simulator tests and the cocotb
testbench.
"""

import random

import numpy as np

from host import codec
from sim.models import frames
from sim.models.frames import Addresses
from spec import records, schedule, wire
from spec.facts import TEST_DMD
from spec.registers import ResetMode, TriggerMode

__all__ = ["DMD", "A", "IMAGE", "image_frame", "app_frame", "sequencer_record", "GOOD_WIRE", "BAD_REGISTERS",
           "BAD_RECORDS", "BAD_CASES", "randomized_mix"]

DMD = TEST_DMD
A = Addresses()
COLUMNS = DMD.columns
PIXELS = DMD.rows * COLUMNS
HEADER = wire.size(records.HEADER)
IMAGE = np.random.default_rng(5).integers(0, 256, (DMD.rows, COLUMNS), dtype=np.uint8)


def image_frame(first_row, rows=1, frame=1, sequence=0):
    """``rows`` rows of :data:`IMAGE` from ``first_row`` in one image record, in a frame."""
    pixels = IMAGE[first_row:first_row + rows].tobytes()
    return frames.udp(A, codec.image_record(frame, first_row * COLUMNS, pixels, sequence))


def app_frame(record):
    return frames.udp(A, record)


def _record(record_type=records.RecordType.IMAGE, body=b"", **head):
    values = {"magic": records.MAGIC, "version": records.VERSION, "type": record_type, "sequence": 0, **head}
    return wire.pack(records.HEADER, values) + body


def _image_body(offset=0, count=COLUMNS):
    return wire.pack(records.IMAGE, {"frame": 2, "offset": offset}) + bytes(count)


def _delta(offset=0, count=COLUMNS, carried=1):
    """A delta record of frame 3 on base 2 (type and body)."""
    body = wire.pack(records.DELTA, {"frame": 3, "base": 2, "carried": carried, "offset": offset})
    return {"record_type": records.RecordType.DELTA, "body": body + bytes(count)}


#: A register set the sequencer can obey (a plan for the test DMD), as the record's wire values.
PLAN = schedule.plan(DMD, 200e6, t_rst_s=200e-9, t_settle_s=300e-9, reset_mode=ResetMode.DUAL)
GOOD_WIRE = records.register_wire(PLAN.params.registers(DMD))


def entry_record(sequence=0, **fields):
    """A sequence entry record as it is (the projector's checks are what is under test)."""
    values = {"index": 0, "slot": 0, "lsb": 0, "dark": 0, "follow": 0, "camera_off": 0, "depth": 0, "skip": 0,
              **fields}
    return _record(records.RecordType.ENTRY, body=wire.pack(records.ENTRY, values), sequence=sequence)


def sequencer_record(sequence=0, **changes):
    return codec.sequencer_record({**GOOD_WIRE, **changes}, sequence)


def _packed(tables):
    """Order tables of eight exponents as the record carries them: entry j of table t in bits
    3(8t + j) up."""
    return sum(e << 3 * (8 * t + j) for t, table in enumerate(tables) for j, e in enumerate(table))


#: Sequencer records the sequencer could not obey: ``name -> changes to a good set``.
BAD_REGISTERS = {
    "lsb_odd": {"lsb": GOOD_WIRE["lsb"] + 1},
    "lsb_zero": {"lsb": 0},
    "order_too_wide": {"order": 4},
    "group_offset_odd": {"group_offsets": 3 << 24},
    "group_zero_offset": {"order": 3, "group_offsets": 4},
    # a plane named twice in the order table; in the last group's table (the others name 0..7)
    "order_table_repeats": {"order": 2, "order_table": _packed([(7, 6, 5, 4, 3, 2, 1, 1)])},
    "group_table_repeats": {"order": 3, "group_tables": _packed([range(8)] * 15 + [(0, 1, 2, 3, 4, 5, 6, 0)])},
    "reset_mode_too_wide": {"reset_mode": 4},
    "chain_not_a_bit": {"chain": 2},
    "stagger_odd": {"stagger": 3},
    "dark_gap_odd": {"dark_gap": GOOD_WIRE["dark_gap"] + 1},
    "row_period_short": {"row_period": DMD.dclk_per_row - 1},
    "lsb_too_short": {"lsb": 2},
    # planes made to hide a load they are too short for; a dark gap too short to load the next plane
    "hide_below_reload": {"hide": 2},
    "dark_gap_short": {"dark_gap": 2},
    "periodic_without_period": {"trigger": TriggerMode.PERIODIC.value, "period": 0},
}

#: Malformed records: ``name -> (record bytes, counter)``.
BAD_RECORDS = {
    "bad_magic": (_record(body=_image_body(), magic=0x1234), "drop_app_magic"),
    "unknown_version": (_record(body=_image_body(), version=records.VERSION + 1), "drop_app_version"),
    "unknown_type": (_record(record_type=9), "drop_app_type"),
    "image_without_pixels": (_record(body=_image_body(count=0)), "drop_app_empty"),
    "truncated_header": (_record()[:4], "drop_app_length"),
    "truncated_image_header": (_record(body=_image_body())[:HEADER + 4], "drop_app_length"),
    "status_query_too_long": (codec.status_query() + b"\0", "drop_app_length"),
    "pixels_beyond_frame": (_record(body=_image_body(offset=PIXELS - COLUMNS + 1)), "drop_app_rows"),
    "offset_beyond_frame": (_record(body=_image_body(offset=PIXELS, count=1)), "drop_app_rows"),
    "delta_without_pixels": (_record(**_delta(count=0)), "drop_app_empty"),
    "truncated_delta_header": (_record(**_delta())[:HEADER + 8], "drop_app_length"),
    "delta_pixels_beyond_frame": (_record(**_delta(offset=PIXELS - COLUMNS + 1)), "drop_app_rows"),
    "delta_without_rows": (_record(**_delta(carried=0)), "drop_app_value"),
    "bit_depth_out_of_range": (codec.control_record(bit_depth=9, armed=1), "drop_app_value"),
    "armed_not_a_bit": (codec.control_record(armed=2), "drop_app_value"),
    "sequence_length_zero": (codec.control_record(sequence_length=0), "drop_app_value"),
    # (the test DMD's 12 KiB frames: the 256 slots an entry names, all in the memory)
    "sequence_beyond_the_slots": (codec.control_record(sequence_length=257), "drop_app_value"),
    "control_too_long": (codec.control_record(armed=1) + b"\0", "drop_app_length"),
    "sequencer_too_long": (sequencer_record() + b"\0", "drop_app_length"),
    "sequencer_truncated": (_record(records.RecordType.SEQUENCER, body=sequencer_record()[HEADER:-1]),
                            "drop_app_length"),
    **{f"sequencer_{name}": (sequencer_record(**changes), "drop_app_value")
       for name, changes in BAD_REGISTERS.items()},
    "entries_beyond_table": (codec.control_record(entries=2049), "drop_app_value"),
    "loop_not_a_bit": (codec.control_record(loop=2), "drop_app_value"),
    "entry_index_beyond_table": (entry_record(index=2048), "drop_app_value"),
    "entry_slot_outside_sequence": (entry_record(slot=255), "drop_app_value"),
    "entry_lsb_odd": (entry_record(lsb=3), "drop_app_value"),
    "entry_dark_odd": (entry_record(dark=1), "drop_app_value"),
    "entry_follow_not_a_bit": (entry_record(follow=2), "drop_app_value"),
    "entry_camera_off_not_a_bit": (entry_record(camera_off=2), "drop_app_value"),
    "entry_depth_over_8": (entry_record(depth=9), "drop_app_value"),
    "entry_skip_over_7": (entry_record(skip=8), "drop_app_value"),
    "entry_too_long": (entry_record() + b"\0", "drop_app_length"),
}

_PAYLOAD = codec.image_record(1, 0, IMAGE[0].tobytes())
#: Every bad input: ``name -> (frame, bad MAC verdict, counter)``.
BAD_CASES = {name: (builder(A, _PAYLOAD), False, counter)
             for name, (builder, counter) in frames.BAD_FRAMES.items()}
BAD_CASES["mac_verdict_bad"] = (frames.udp(A, _PAYLOAD), True, "drop_mac")
BAD_CASES.update({name: (app_frame(record), False, counter)
                  for name, (record, counter) in BAD_RECORDS.items()})


def randomized_mix(count=260, seed=12):
    """``count`` frames ``(bytes, bad MAC verdict)`` at random: image records that split rows
    anywhere, mostly continuing the frame, now and then jumping or starting another frame (and
    now and then one skipping a sequence number), ARP requests, ICMP echoes of random length,
    status queries, control records with random values, sequencer records good and bad, and bad
    inputs from :data:`BAD_CASES`. (The default seed's mix has sequence entries taken, which the
    endpoint's testbench requires of it.)"""
    rng = random.Random(seed)
    sequence = []
    seq = 0
    bad_cases = list(BAD_CASES.values())
    flat = IMAGE.tobytes()
    offset, frame = 0, 1
    for _ in range(count):
        roll = rng.random()
        if roll < 0.5:
            if rng.random() < 0.1:
                offset, frame = rng.randrange(PIXELS), frame + rng.choice([0, 1, 7])
            size = min(rng.choice([1, 5, COLUMNS - 1, COLUMNS, 2 * COLUMNS + 9, 500]), PIXELS - offset)
            record = codec.image_record(frame, offset, flat[offset:offset + size], seq)
            offset = (offset + size) % PIXELS
            raw, bad = frames.udp(A, record), False
            seq += 1 if rng.random() < 0.95 else 2
        elif roll < 0.56:
            raw, bad = frames.arp_request(A), False
        elif roll < 0.62:
            raw, bad = frames.icmp_echo(A, rng.randbytes(rng.randrange(0, 64))), False
        elif roll < 0.65:
            raw, bad = frames.udp(A, codec.status_query(seq)), False
            seq += 1
        elif roll < 0.69:
            control = codec.control_record(seq, bit_depth=rng.randrange(0, 10),
                                           sequence_length=rng.randrange(0, 3),
                                           software_trigger=rng.random() < 0.7, sequence_start=rng.random() < 0.6)
            raw, bad = frames.udp(A, control), False
            seq += 1
        elif roll < 0.74:
            # (one draw whatever the table's length, so that a bad set added to it leaves the
            # rest of the mix as it was)
            bad_set = list(BAD_REGISTERS.values())[int(rng.random() * len(BAD_REGISTERS))]
            changes = rng.choice([{"lsb": 2 * rng.randrange(GOOD_WIRE["lsb"] // 2, 1 << 20)}, bad_set])
            raw, bad = frames.udp(A, sequencer_record(seq, **changes)), False
            seq += 1
        elif roll < 0.78:
            # entries, mostly good: the slot against the sequence in force, odd times, flags, skips
            entry = entry_record(seq, index=rng.choice([0, 7, 2047, 2048]), slot=rng.choice([0, 0, 1, 2]),
                                 lsb=2 * rng.randrange(5) + (rng.random() < 0.2), dark=2 * rng.randrange(4),
                                 follow=rng.choice([0, 1, 0, 1, 2]), skip=rng.choice([0, 0, 3, 7, 8]))
            raw, bad = frames.udp(A, entry), False
            seq += 1
        else:
            raw, bad, _ = rng.choice(bad_cases)
        sequence.append((raw, bad))
    return sequence
