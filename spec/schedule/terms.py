"""The schedule's terms: what the model and the planner count in.

The ``dmd`` domain's clock, the sequencer pipeline's fixed latencies, a plan's parameters
(:class:`Params`), a frame offered (:class:`Frame`), a run's outcome (:class:`Result`), the
row cycle and the time a reload takes (:func:`reload_bound`).
"""

import math
from dataclasses import dataclass, field

from ..facts import LIGHT, TIMING, BlockMode
from ..registers import (
    MAX_GROUPS,
    MIN_SETTLE,
    PlaneOrder,
    ResetMode,
    Source,
    TriggerMode,
    group_size,
    lead_cycles,
)

__all__ = [
    "Params", "Frame", "Result", "exponents", "groups", "pulse_encoding", "FABRIC_HZ", "beats_at",
    "row_cycles", "row_rate_words", "INIT_TO_DVALID", "RELOAD_LEAD", "WORD_FIFO_ROWS", "flush_rows",
    "PAPER_SETTLE_CYCLES", "MIN_SETTLE", "RST_MARGIN", "FALL_LATENCY", "DECISION_TO_PINS",
    "PACE_LAG", "MIRRORS_SETTLED", "LIGHT_RISE", "LIGHT_FALL", "even", "trigger_lead", "reload_bound", "reload_cycles",
]


#: The ``dmd`` domain's clock: every cycle count of the model and the sequencer is in its cycles.
#: DCLK is this (one beat per cycle) or twice this (two beats per cycle: 400 MHz through the
#: platform's 4:1 serialisers).
FABRIC_HZ = 200e6


def row_rate_words(dmd, dclk_hz):
    """64-bit store words a ``dmd`` cycle that feed a row at the row cycle (every bus, every
    beat): 1 for the DLP7000 at DCLK 200 MHz, 2 at 400 MHz, 4 for the DLP9500 at 400 MHz."""
    return dmd.bits_per_dclk * beats_at(dclk_hz) // 64


def beats_at(dclk_hz):
    """DCLK beats per ``dmd`` cycle at DCLK ``dclk_hz``: 1 at 200 MHz, 2 at 400 MHz."""
    beats = round(dclk_hz / FABRIC_HZ)
    if beats not in (1, 2) or abs(beats * FABRIC_HZ - dclk_hz) > 1:
        raise ValueError(f"DCLK {dclk_hz / 1e6:g} MHz is not 1 or 2 beats per {FABRIC_HZ / 1e6:g} MHz cycle")
    return beats


def row_cycles(dmd, beats=1):
    """``dmd`` cycles of one row cycle: the DMD's DCLK cycles per row over the beats per cycle."""
    assert dmd.dclk_per_row % beats == 0
    return dmd.dclk_per_row // beats


def trigger_lead(dmd, beats=1):
    """The least offset of group 0 in GROUPS by which a trigger may come while other groups'
    loads run (:meth:`_Model.steady`): :func:`spec.registers.lead_cycles` of ``dmd``."""
    return lead_cycles(row_cycles(dmd, beats), dmd.clear_row_cycles)


def _at_least(seconds):
    """The least whole number of cycles that lasts ``seconds``."""
    return math.ceil(seconds * FABRIC_HZ - 1e-9)


#: Cycles from a clocking pulse on the pins to its mirrors settled: the pulse to the start of
#: their motion, then the switching time (crossover and settling). A gated plane's light comes
#: no sooner.
MIRRORS_SETTLED = _at_least(TIMING["t_pulse_to_mirror"].value + TIMING["t_switch"].value)
#: Cycles the light source takes to reach full light after the gate rises, and to go dark after
#: it falls (assumptions: :data:`spec.facts.LIGHT`).
LIGHT_RISE = _at_least(LIGHT["t_rise"].value)
LIGHT_FALL = _at_least(LIGHT["t_fall"].value)


#: First load this many cycles after INIT_ACTIVE falls (DLPC910: first DVALID >= 64 clocks).
INIT_TO_DVALID = int(TIMING["init_to_dvalid_clocks"].value)


#: Cycles from a group's last dark pulse (the decision) to the first a trigger may be obeyed at,
#: when that pulse is what the trigger waits for (GROUPS): the pulse is applied, then the planner
#: registers its groups' rest, which the frame control reads.
END_TO_TRIGGER = 3


#: Default ``reload_lead``: a frame taken while waiting for a trigger has its first row loaded
#: this many cycles later at the earliest (the requester's occupancy look-up and the store's
#: first words of the row; enough for the test store, set per store at run time).
RELOAD_LEAD = 16


#: The sequencer's word FIFO holds this many rows.
WORD_FIFO_ROWS = 4


def flush_rows(dmd):
    """Rows of stale words a newer frame may find asked for when it abandons a preload: the
    block the store is answering, the block request held until taken, the word FIFO and one row
    of latency. At one row per ``row_period`` they are discarded within
    ``flush_rows * row_period`` cycles (the store's own look-ahead beyond that belongs in
    ``reload_lead``)."""
    return 2 * dmd.rows_per_block + WORD_FIFO_ROWS + 1


#: Under the four-DMD paper's settle reading a group's memory may change as soon as RST_ACTIVE
#: falls; the sequencer learns of the fall through its synchroniser, and its settle countdown
#: follows the RST_ACTIVE countdown (:data:`spec.registers.MIN_SETTLE`), so the plan keeps this
#: as its ``t_settle`` (TI's settle covers it).
PAPER_SETTLE_CYCLES = MIN_SETTLE


#: Cycles from a decision to the command on the pins: the decision is registered, then the
#: command registers.
DECISION_TO_PINS = 2


#: Cycles from RST_ACTIVE falling at the pin to its fall in the sequencer (a two-flip-flop
#: synchroniser).
FALL_LATENCY = 2


#: Cycles added to the RST_ACTIVE time: the command leaves :data:`DECISION_TO_PINS` cycles after
#: its decision, RST_ACTIVE rises the cycle after, and the sequencer sees it through its
#: synchroniser; ``t_rst`` must cover the pin's high time plus this.
RST_MARGIN = DECISION_TO_PINS + 1 + FALL_LATENCY


#: A load operation waits for the oldest dark pulse's clears only from this many cycles after
#: that group's RST_ACTIVE count ends (the sequencer's settle countdown starts as it ends, and
#: its flags are registered twice on their way to the bus).
CLEAR_HOLD_AFTER_RST = 4


#: A trigger's pace reaches the frame control's newer-frame guard this many cycles after the
#: trigger (the guard's thresholds, the interval plus an eighth and the interval less
#: :func:`reload_bound`, are summed in a pipeline of the gateware, the trigger registered first).
PACE_LAG = 7


#: Cycles from the store's offer of a frame to the sequencer's decisions seeing it (the planner
#: registers the offer).
OFFER_LAG = 1


def even(t):
    """Round a cycle count up to even."""
    return t + (t & 1)


@dataclass
class Params:
    """Run-time parameters, as in :class:`gateware.registers.Registers` (cycles)."""
    lsb: int
    t_rst: int
    t_settle: int
    hide: int
    dark_gap: int
    reset_mode: ResetMode = ResetMode.GLOBAL
    order: PlaneOrder = PlaneOrder.MSB_FIRST
    order_table: tuple = (7, 6, 5, 4, 3, 2, 1, 0)
    anchor: int = 0
    chain: bool = False
    strict_rst: bool = True
    trigger: TriggerMode = TriggerMode.EXTERNAL
    trigger_hold: bool = False
    source: Source = Source.STORE
    stagger: int = 0
    row_period: int = 0          # 0: DCLK-per-row of the DMD
    reload_lead: int = RELOAD_LEAD
    period: int = 0
    camera_offset: int = 0
    camera_width: int = 1
    ns_flip: bool = False
    park: bool = False
    beats: int = 1               # DCLK beats per dmd cycle: the sequencer's build, not a register
    t_flip: int = 0              # the four-DMD paper's settle reading: a group's pulses at least this
                                 # far apart (t_settle 0: memory loads once RST_ACTIVE falls); 0: TI's
    # with ``order`` GROUPS: each group's own order table and first pulse's offset (plans beyond
    # one timeline, in place of ``order_table`` and ``g * stagger``), one entry a group
    group_tables: tuple = ()
    group_offsets: tuple = ()
    # gated planes (the gate pin switches the light): bit e of ``gated_planes`` gates the plane of
    # weight 2**e, which lasts ``gated_time``, its light on ``light_times[e]`` from ``light_lead``
    # after its pulse
    gated_planes: int = 0
    gated_time: int = 0
    light_lead: int = 0
    light_times: tuple = (0,) * 8

    def __post_init__(self):
        if (self.order == PlaneOrder.GROUPS) != bool(self.group_tables) or \
                len(self.group_tables) != len(self.group_offsets) or len(self.group_tables) > MAX_GROUPS:
            raise ValueError("PlaneOrder.GROUPS takes an order table and an offset for each group, and only it")

    def registers(self, dmd):
        """The values of :class:`~gateware.registers.Registers`, as a dict."""
        regs = {k: getattr(self, k) for k in (
            "lsb", "t_rst", "t_settle", "hide", "dark_gap", "stagger", "period", "reload_lead",
            "camera_offset", "camera_width", "anchor", "gated_planes", "gated_time", "light_lead")}
        unused = MAX_GROUPS - len(self.group_tables)
        tables = [list(t) + list(range(len(t), 8)) for t in self.group_tables] + [list(range(8))] * unused
        regs.update(reset_mode=self.reset_mode, order=self.order, order_table=list(self.order_table),
                    group_tables=[e for t in tables for e in t],
                    # (the unused groups' as group 0's: none below it)
                    group_offsets=list(self.group_offsets) + list(self.group_offsets[:1] or [0]) * unused,
                    chain=int(self.chain), strict_rst=int(self.strict_rst), trigger=self.trigger,
                    trigger_hold=int(self.trigger_hold),
                    source=self.source, row_period=self.row_period or row_cycles(dmd, self.beats),
                    ns_flip=int(self.ns_flip), park=int(self.park), light_times=list(self.light_times))
        return regs

    def gated(self, e):
        """Whether the plane of weight ``2**e`` is gated."""
        return bool(self.gated_planes >> e & 1)

    def plane_time(self, e, lsb=0):
        """The plane of weight ``2**e``'s time, pulse to pulse: ``gated_time`` if it is gated, else
        ``lsb`` (a frame's own, 0: the register's) shifted by ``e``."""
        return self.gated_time if self.gated(e) else (lsb or self.lsb) << e


@dataclass
class Frame:
    """A frame the store offers: its slot, bit depth and occupancy (blocks,) bytes, bit k =
    stored plane k has a bit set in the block (:func:`sim.models.bitplane_model.occupancy`); and how
    a sequence entry shows it (the defaults: as the registers say). It shows stored planes
    ``8 - depth - skip .. 7 - skip`` (``skip``: a sequence entry's planes left out above them)."""
    slot: int
    depth: int
    occupancy: tuple = None      # None: every block full
    ready: int = 0               # cycle from which the store offers it
    sequence: bool = False       # the next of a stored sequence: never replaces a waiting frame
    lsb: int = 0                 # its least significant plane's time (0: the register's)
    dark: int = 0                # at least this long dark after it before a frame that follows
    follow: bool = False         # starts as soon as the frame before it ends, with no trigger
    camera_off: bool = False     # no camera trigger for it
    last: bool = False           # the last entry of a sequence played once: nothing follows it,
                                 # and triggers after it starts are ignored (``ended``)
    skip: int = 0                # its stored planes left out above those it shows

    def stored_plane(self, e):
        """The stored plane of the plane of weight ``2**e``."""
        return 8 - self.depth - self.skip + e

    def occupied(self, plane, block):
        return self.occupancy is None or bool((self.occupancy[block] >> plane) & 1)


@dataclass
class Result:
    commands: list               # (cycle, kind, arg): row/row, clear/block, noop/None, pulse/blocks
    pulses: list                 # (cycle, group, kind, frame_index, exponent or None for dark)
    late: int = 0
    overruns: int = 0
    held: int = 0                # triggers held until every group was ready
    ended: int = 0               # triggers ignored after a sequence played once had ended
    bad_frames: int = 0
    loads_held: int = 0          # decisions at which a load operation waited for a dark's clears
    accepted: list = field(default_factory=list)   # cycles triggers were obeyed (strobe or held)
    frame_starts: list = field(default_factory=list)
    camera_starts: list = field(default_factory=list)  # frame starts whose frame pulses the camera
    shown: list = field(default_factory=list)        # frames taken, in order

    def decoded(self):
        """The commands a decoder of the pins logs: the no-op rows that follow a 1080p clear
        carry no command and are left out."""
        return [c for c in self.commands if c[1] != "noop"]


def exponents(order, table, depth, anchor=0):
    """Weight exponents (0 = least significant) in display order for a frame of ``depth``: the
    order's, started at its position ``anchor`` (modulo ``depth``) and wrapped round."""
    if order == PlaneOrder.MSB_FIRST:
        exps = list(range(depth - 1, -1, -1))
    elif order == PlaneOrder.LSB_FIRST:
        exps = list(range(depth))
    else:
        exps = [int(e) for e in table[:depth]]
        assert sorted(exps) == list(range(depth)), "order table must be a permutation"
    start = anchor % depth
    return exps[start:] + exps[:start]


def groups(dmd, mode):
    """List of block lists, one per pulse group."""
    size = group_size(mode, dmd.blocks)
    return [list(range(b, min(b + size, dmd.blocks))) for b in range(0, dmd.blocks, size)]


def pulse_encoding(dmd, mode, g):
    """(BLKMD, BLKAD, RST2BLKZ) of group ``g``'s clocking pulse (facts: block commands)."""
    mode = ResetMode(mode)
    if mode == ResetMode.GLOBAL:
        return BlockMode.MULTI, 0b1000, 1
    if mode == ResetMode.QUAD:
        return BlockMode.MULTI, g << 1, 1
    if mode == ResetMode.DUAL:
        return BlockMode.MULTI, g, 0
    return BlockMode.RESET, g, 1


def reload_bound(dmd, p):
    """Cycles a newer frame taken while the groups wait may need before every group is loaded
    again, at most: the frame control's decision, the flush of stale words, the reload lead,
    queueing the first planes, every row of the first planes at the row period, and a row
    cycle's slack for the bus's parity."""
    return reload_cycles(dmd, p.beats, max(p.row_period, row_cycles(dmd, p.beats)), p.reload_lead)


def reload_cycles(dmd, beats, row_period, reload_lead):
    """:func:`reload_bound` of a ``row_period`` of at least a row cycle and a ``reload_lead``:
    operators only, so that the gateware builds the same sum from its registers."""
    return (flush_rows(dmd) + dmd.rows) * row_period + reload_lead + dmd.blocks + 3 + 2 * row_cycles(dmd, beats)
