"""The sequencer's run-time registers and their modes, in plain Python.

Every duration is a cycle count of the ``dmd`` domain, set at run time by a sequencer record;
nothing in the gateware bakes in a frame rate, an exposure or a TI timing number. The host
computes a consistent set with :func:`spec.schedule.plan`, which also says which constraint
binds.

:data:`FIELDS` is the one definition of the register set: the gateware builds its struct from it
(:mod:`gateware.registers`), the protocol puts it on the wire field by field
(:data:`spec.records.SEQUENCER`), and the host and the models read and write it as ints.
"""

import enum

__all__ = ["ResetMode", "PlaneOrder", "TriggerMode", "Source", "FIELDS", "Field",
           "TIME_BITS", "LSB_BITS", "DURATION_BITS", "MIN_SETTLE", "MIN_CHAINED", "TIMED_NOTICE", "MAX_GROUPS",
           "lead_cycles", "clear_cycles", "group_blocks", "group_size", "layout_bits", "pack", "unpack"]

#: Width of the free-running time base. Comparisons are made on differences, so the base may
#: wrap (every 8 days at 400 MHz) without harm; every wait is shorter than 2**(TIME_BITS-1).
TIME_BITS = 48
#: Width of the least significant plane's duration: up to 2**32 cycles (10.7 s at 400 MHz).
LSB_BITS = 32
#: Width of any plane duration (LSB shifted by up to 7) and of the other long waits.
DURATION_BITS = LSB_BITS + 8
#: Pulse groups the per-group registers hold: the most any DMD has (the DLP7000's 16 blocks,
#: single reset).
MAX_GROUPS = 16
#: The shortest ``t_settle`` the sequencer keeps exactly: its settle countdown starts the cycle
#: after its RST_ACTIVE countdown ends, and a countdown's flags are registered.
MIN_SETTLE = 3
#: The shortest ``stagger`` or group offset (not 0) the sequencer keeps exactly: a first pulse
#: timed from the timer before it is known as due two registered stages after that timer ends.
MIN_CHAINED = 4
#: Cycles after the pulses a trigger times at once (two after it) that the bus may still start an
#: operation without knowing of a first pulse timed from them (the timer before it has just
#: ended, and its flags are registered): such an operation must end by that pulse.
TIMED_NOTICE = 2


def lead_cycles(row_cycles, clear_row_cycles):
    """The least offset of group 0 (not 0) by which a trigger may come while other groups' loads
    run: the bus's longest operation (a row, or a block's clear) under way when it comes, or
    started before the bus knows of the pulse (:data:`TIMED_NOTICE`), ends by the pulse, which
    keeps its time (:data:`MIN_CHAINED`); even."""
    lead = max(max(1, clear_row_cycles) * row_cycles + TIMED_NOTICE, MIN_CHAINED)
    return lead + (lead & 1)


def clear_cycles(row_cycles, clear_row_cycles):
    """Cycles one block clear takes on the bus: its row cycles, rounded up to even (the bus
    decides on even cycles only, so a clear of an odd length holds the bus a cycle more)."""
    cycles = clear_row_cycles * row_cycles
    return cycles + (cycles & 1)


def group_blocks(mode, blocks):
    """Blocks in the largest group of a reset mode on a DMD of ``blocks`` blocks."""
    return min(group_size(mode, blocks), blocks)


class ResetMode(enum.IntEnum):
    """Which blocks one mirror clocking pulse covers (DLPC410 block commands)."""
    GLOBAL = 0   # all blocks together (BLKMD=11, BLKAD=10xx)
    QUAD = 1     # blocks 4q..4q+3, phased (BLKMD=11, BLKAD=0qq0, RST2BLKZ=1)
    DUAL = 2     # blocks 2p, 2p+1, phased (BLKMD=11, BLKAD=0ppp, RST2BLKZ=0)
    SINGLE = 3   # one block, phased (BLKMD=10)


class PlaneOrder(enum.IntEnum):
    """Display order of a frame's planes."""
    MSB_FIRST = 0
    LSB_FIRST = 1
    TABLE = 2    # ``order_table[j]`` = weight exponent (0 = least significant) shown j-th
    GROUPS = 3   # group g shows ``group_tables[8g + j]`` j-th, its first pulse ``group_offsets[g]``
                 # after group 0's (in place of ``g * stagger``): plans beyond one timeline


class TriggerMode(enum.IntEnum):
    """What starts a frame."""
    EXTERNAL = 0   # rising edge of the TTL trigger input
    PERIODIC = 1   # free-running, every ``period`` cycles
    SOFTWARE = 2   # a pulse on the ``soft_trigger`` port (a control record)
    SYNC = 3       # rising edge of the sync input: tiled projectors start their first plane
                   # together (MSB_FIRST: the most significant plane on every board at once)


class Source(enum.IntEnum):
    """Where row data comes from."""
    STORE = 0      # planes read from the frame store
    PRNG = 1       # on-chip Bernoulli(1/2) patterns, 1-bit frames, no memory bandwidth


def group_size(mode, blocks):
    """Blocks per clocking-pulse group for a reset mode."""
    return {ResetMode.GLOBAL: blocks, ResetMode.QUAD: 4, ResetMode.DUAL: 2,
            ResetMode.SINGLE: 1}[ResetMode(mode)]


class Field:
    """One register: ``width`` bits, or ``count`` entries of ``width`` bits; ``enum`` its modes."""

    def __init__(self, name, width, *, enum=None, count=None, doc=""):
        self.name, self.width, self.enum, self.count, self.doc = name, width, enum, count, doc

    @property
    def bits(self):
        return self.width * (self.count or 1)


#: The registers in struct order (least significant bits first), all durations in ``dmd`` cycles.
FIELDS = [
    Field("reset_mode", 2, enum=ResetMode, doc="pulse grouping"),
    Field("order", 2, enum=PlaneOrder, doc="plane order"),
    Field("order_table", 3, count=8,
          doc="with PlaneOrder.TABLE: entry j is the weight exponent shown j-th"),
    Field("chain", 1, doc="frames follow one another without a trigger once the first trigger "
                          "started them (binary pattern mode, continuous PWM); otherwise every "
                          "frame waits for its trigger"),
    Field("strict_rst", 1, doc="1: no pulse of any group while RST_ACTIVE may be high from any "
                               "pulse (the strict reading); 0: only pulses of the same group wait "
                               "for each other"),
    Field("trigger", 2, enum=TriggerMode, doc="trigger mode"),
    Field("source", 1, enum=Source, doc="row-data source"),
    Field("lsb", LSB_BITS, doc="duration of the least significant plane (even); the plane of "
                               "weight 2**e lasts lsb << e"),
    Field("t_rst", 16, doc="RST_ACTIVE time"),
    Field("t_settle", 16, doc="mirror settle time after RST_ACTIVE: a pulsed group's memory "
                              "changes no sooner than t_rst + t_settle after its pulse"),
    Field("hide", DURATION_BITS, doc="a plane at least this long has the next plane loaded "
                                     "behind it; shorter planes are ended by a dark pulse of "
                                     "cleared blocks"),
    Field("dark_gap", DURATION_BITS, doc="from a dark pulse to the next plane's pulse (covers "
                                         "settle and the reload)"),
    Field("stagger", 24, doc="cycles between the pulses of consecutive groups (phased); even"),
    Field("row_period", 8, doc="cycles from one row load to the next (at least DCLK-per-row; "
                               "sets the memory bandwidth)"),
    Field("reload_lead", 16, doc="a frame taken while every group waits for a trigger has its "
                                 "first plane loaded no sooner than this many cycles later (the "
                                 "requester's occupancy look-up plus the store's latency to the "
                                 "first words of a row)"),
    Field("period", DURATION_BITS, doc="trigger period of TriggerMode.PERIODIC; in SYNC, the sync "
                                       "master's period, for the board's clock loop (0: off)"),
    Field("camera_offset", DURATION_BITS, doc="camera-trigger pulse: starts this many cycles "
                                              "after a frame's first pulse"),
    Field("camera_width", 16, doc="camera-trigger pulse length"),
    Field("ns_flip", 1, doc="NS_FLIP pin"),
    Field("park", 1, doc="PWR_FLOAT (park the mirrors)"),
    Field("trigger_hold", 1, doc="1: a trigger that comes while a frame plays or loads is held and "
                                 "obeyed on the first cycle every group is ready (one at a time; a "
                                 "second one meanwhile is an overrun); 0: it is an overrun"),
    Field("anchor", 3, doc="the display position a frame starts at: its planes are shown in the "
                           "plane order from position anchor (modulo the frame's depth), wrapping "
                           "round to the order's first; the trigger (in SYNC, the sync pulse) "
                           "lands on that plane. 0: the order as it is"),
    Field("group_tables", 3, count=8 * MAX_GROUPS,
          doc="with PlaneOrder.GROUPS: entry 8g + j is the weight exponent group g shows j-th"),
    Field("group_offsets", 24, count=MAX_GROUPS,
          doc="with PlaneOrder.GROUPS: entry g is the cycles from the first pulse a trigger times "
              "at once to group g's first pulse (0: at once; even, 0 or at least a block clear's "
              "row cycles, as stagger; group 0's 0: its first pulse starts the frame)"),
    Field("gated_planes", 8, doc="bit e: the plane of weight 2**e is gated: it lasts gated_time, and "
                                 "the light source (the gate pin) is on only for its light_times[e], "
                                 "light_lead after its pulse. 0: no plane gated, the gate stays on"),
    Field("gated_time", 24, doc="duration of a gated plane (even; the shortest legal plane: the "
                                "mirrors' settle and the reload)"),
    Field("light_lead", 16, doc="from a gated plane's pulse to its light on (the mirrors settled)"),
    Field("light_times", 24, count=8,
          doc="entry e: the light's on-time in the gated plane of weight 2**e (the host trims each)"),
]

_BY_NAME = {f.name: f for f in FIELDS}


def layout_bits():
    """``{name: (offset, bits)}`` of each register in the packed set (first field lowest)."""
    out, at = {}, 0
    for f in FIELDS:
        out[f.name] = (at, f.bits)
        at += f.bits
    return out


def _int(name, value):
    f = _BY_NAME[name]
    if f.count:
        value = list(value)
        assert len(value) == f.count, f"{name}: {f.count} entries"
        return sum((int(v) & ((1 << f.width) - 1)) << (f.width * i) for i, v in enumerate(value))
    return int(value)


def pack(values):
    """Register values (``{name: int, enum member or list}``, missing ones 0) -> the packed set
    as an int, as the gateware's struct holds it."""
    unknown = set(values) - set(_BY_NAME)
    if unknown:
        raise KeyError(f"not registers: {sorted(unknown)}")
    acc = 0
    for name, (offset, bits) in layout_bits().items():
        value = _int(name, values.get(name, 0))
        if not 0 <= value < (1 << bits):
            raise ValueError(f"register {name}={value} does not fit {bits} bits")
        acc |= value << offset
    return acc


def unpack(bits):
    """The packed set (an int) -> ``{name: int}`` (the entries of a table as a list)."""
    out = {}
    for name, (offset, width) in layout_bits().items():
        raw = (bits >> offset) & ((1 << width) - 1)
        f = _BY_NAME[name]
        out[name] = [(raw >> (f.width * i)) & ((1 << f.width) - 1) for i in range(f.count)] if f.count else raw
    return out
