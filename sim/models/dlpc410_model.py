"""Behavioural model of a DLPC410 controller and its DMD, with rule checking.

:class:`Dlpc410` reads the applications interface of :mod:`gateware.dlpc410.interface` one
``dmd`` cycle at a time (:meth:`Dlpc410.step`), decodes row cycles beat by beat through the bit
map of :mod:`gateware.dlpc410.beat`, keeps the DMD's memory and mirror state as numpy arrays,
applies block clears and mirror clocking pulses, drives INIT_ACTIVE, RST_ACTIVE and
ECP2_FINISHED, and raises :class:`RuleBreak` the moment the driver breaks one of the rules in
:data:`RULES`. Each rule is checked in exactly one place and named after its source, so a failing
test reads like the document it breaks::

    RuleBreak: DLPA008B 4.1 settle: row 37 of block 0 written 1203 cycles after RST_ACTIVE fell,
    needs 1600 (cycle 52311)

Thin adapters connect the one model to the two simulators: :func:`amaranth_process` (an async
process for :mod:`amaranth.sim`) and :class:`CocotbAdapter` (a coroutine for cocotb on the generated
Verilog). :mod:`sim.models.camera_model` turns the recorded mirror history into the image a sensor
integrates.

Signals
-------
:meth:`Dlpc410.step` takes a dict keyed by the interface's member names with plain ints, one
``dmd`` cycle of ``beats`` DCLK cycles: ``din_a``.. ``din_d`` are the packed
:func:`~gateware.dlpc410.interface.din_layout` (edge ``k`` in bits ``16k .. 16k + 15``: the
first DCLK cycle's rising edge, its falling edge, the next cycle's ...), ``dvalid`` one bit per
edge (DVALID is read on each DCLK cycle's rising edge, bit ``2b`` for beat ``b``; its other edges
carry only the training pattern), enums are their integer encodings. Missing keys read as the
interface's reset values. It returns the controller's outputs for the next cycle.

Cycle conventions
-----------------
Cycle ``c`` is the ``c``-th call of :meth:`Dlpc410.step` (or cycle skipped by
:meth:`Dlpc410.idle`), a ``dmd`` cycle; the timing rules are counted in these cycles, the
row-cycle length and the idle-gap rule in DCLK cycles. A row cycle's commands take effect at
the cycle of its first beat ``c``: a clock
pulse latches memory into mirrors there, a clear empties the block there, and the row's data is
written at the end of the row cycle but counted as written at ``c`` by the settle rule. After a
pulse at ``p``, RST_ACTIVE is high on cycles ``p + 1 .. p + rst_active_cycles`` and *falls* at
``f = p + rst_active_cycles + 1``; a pulsed block's memory may change again from
``f + settle_cycles`` on.

Assumptions where the TI documents are uncertain (see also ``docs/dlpc410_model.md``)
------------------------------------------------------------------------------------
* ROWMD 01 and 11 (DLPC910, refHDL): 11 sets the row pointer to the first row and writes there,
  01 advances it and writes. With NS_FLIP high the *first* row is the last one (rows - 1) and 01
  decrements. ROWMD 10 writes at ROWAD and also moves the pointer there. The pointer is unset
  after initialisation; 01 with no pointer, or stepping past either end, breaks the row rule
  (DLPA008B: the pointer does not wrap).
* NS_FLIP and COMP_DATA are sampled with the row cycle; COMP_DATA stores the complement. Like
  ROWMD, ROWAD, BLKMD, BLKAD and RST2BLKZ they must be held through the row cycle.
* Block commands (refHDL, confidence medium): dual and quad groups that reach past the last block
  (DLP9500 has 15) pulse the blocks that exist; a group with none is a block-address break.
* A clear occupies ``clear_row_cycles`` row cycles (:mod:`~spec.facts`): its own,
  whose ROWMD must be 00, then no-op rows (ROWMD 00, no second clear, no pulse of the block
  being cleared; a pulse of other blocks may ride on them). Idle gaps do not count.
* Open question (facts ``t_rst_active``; ``docs/dlpc410_model.md``): with ``strict_rst_active``
  (default) no pulse may start while RST_ACTIVE is high; with it off, a pulse may start while
  RST_ACTIVE is high from a pulse of other blocks, never of its own blocks.
* Settle: any write (row or clear) to a block from its pulse until ``settle_cycles`` after its
  RST_ACTIVE fell breaks the rule, whether or not the data differ (TI's reading, the default).
  Under the four-DMD paper's reading (``reading="paper"``, never the default) a write breaks it
  only while RST_ACTIVE is high, and a block's pulse sooner than ``settle_cycles`` after its last
  breaks ``flip``.
* Initialisation: INIT_ACTIVE is high while ARSTZ is low and for ``init_cycles`` after ARSTZ
  rises (counting from ECP2_FINISHED if that comes later). The training pattern (DLPC410
  datasheet: a repeating ``0100`` on every data pin, any phase; four edges = two cycles) must be on
  every data pin from two cycles before ARSTZ rises until INIT_ACTIVE falls; DVALID's share of the
  pattern is the platform layer's (the core has one DVALID bit per cycle) and is not checked.
  ROWMD and BLKMD must stay 00 meanwhile. DVALID must stay low for ``init_to_dvalid_clocks``
  after INIT_ACTIVE falls, except that ``init_grace_cycles`` (default 0) lets the training
  pattern, DVALID included, run on for the FPGA's synchroniser latency. ARSTZ falling again
  resets memory, mirrors and pointer to zero.
* A restart (a controller fault the tests inject: ``restart_at``): INIT_ACTIVE high again for
  ``restart_cycles`` from that cycle, ECP2_FINISHED low for the first ``restart_ecp2_cycles`` of
  them (the controller reconfigured). The DMD's memory, mirrors and row pointer go to zero and
  the row cycle under way is lost. The FPGA sees INIT_ACTIVE a synchroniser later: for
  ``restart_grace_cycles`` the pins are ignored; then the rules of initialisation hold as at
  start-up (no command, the training pattern, DVALID low for ``init_to_dvalid_clocks`` after
  INIT_ACTIVE falls).
* Mirrors start at 0 (off). WDT_ENBLZ and PWR_FLOAT are not modelled.
* DLP650LNIR (32 bits per DCLK, odd pins of A and B) is not modelled: the bit map for it is not
  in :mod:`gateware.dlpc410.beat`.
"""

import math
from dataclasses import dataclass

import numpy as np

from gateware.dlpc410.beat import PINS_PER_BUS, lanes_to_word
from spec.facts import SETTLE_READINGS, TIMING, BlockMode, RowMode

__all__ = ["Rule", "RULES", "RuleBreak", "Command", "Dlpc410", "timing_cycles",
           "INPUTS", "OUTPUTS", "amaranth_process", "CocotbAdapter"]


@dataclass(frozen=True)
class Rule:
    """One rule of the DLPC410 interface: ``source`` names the document, ``title`` the rule."""
    name: str
    source: str
    title: str


class RuleBreak(AssertionError):
    """The driver broke :attr:`rule` at :attr:`cycle`."""

    def __init__(self, rule, cycle, detail):
        self.rule, self.cycle, self.detail = rule, cycle, detail
        super().__init__(f"{rule.source} {rule.title}: {detail} (cycle {cycle})")


_RULES = [
    Rule("rst_active", "DLPC410 RST_ACTIVE (forum)", "pulse while RST_ACTIVE"),
    Rule("settle", "DLPA008B 4.1", "settle"),
    Rule("flip", "four-DMD eq. 6-7 (the paper's settle reading)", "pulse while the block settles"),
    Rule("clear_overlap", "DLPA008B 4.2", "clear overlapping a row load"),
    Rule("dvalid_gap", "DLPU045A", "odd DVALID idle gap"),
    Rule("row_cycle", "DLPC410 row addressing", "row cycle cut short"),
    Rule("row_hold", "DLPC410 row addressing", "row command not held"),
    Rule("row_address", "DLPC410 row addressing", "row address beyond the array"),
    Rule("row_pointer", "DLPA008B", "row pointer"),
    Rule("block_address", "refHDL block commands", "block address"),
    Rule("init_command", "DLP7000 8.3", "command during initialisation"),
    Rule("init_training", "DLPC410 training pattern", "training pattern"),
    Rule("init_dvalid", "DLPC910", "DVALID too soon after INIT_ACTIVE fell"),
]
#: Every rule the model checks, by name.
RULES = {rule.name: rule for rule in _RULES}

#: Interface members the model reads (see :class:`gateware.dlpc410.interface.Signature`).
INPUTS = ("din_a", "din_b", "din_c", "din_d", "dvalid", "rowmd", "rowad", "blkmd", "blkad",
          "rst2blkz", "comp_data", "ns_flip", "wdt_enblz", "pwr_float", "arstz")
#: Interface members the model drives.
OUTPUTS = ("init_active", "rst_active", "ecp2_finished", "dmd_type", "ddc_version")

_DEFAULTS = {"rst2blkz": 1, "wdt_enblz": 1}
#: Sampled on a row cycle's first cycle and held for its length (interface contract).
_HELD = ("rowmd", "rowad", "blkmd", "blkad", "rst2blkz", "comp_data", "ns_flip")


def _held(signals):
    return tuple(signals.get(name, _DEFAULTS.get(name, 0)) for name in _HELD)


def timing_cycles(dclk):
    """The timing rules of :data:`spec.facts.TIMING` in cycles of ``dclk`` Hz,
    rounded up (never laxer than the fact)."""
    def cycles(key):
        return math.ceil(round(TIMING[key].value * dclk, 6))
    return {
        "rst_active_cycles": cycles("t_rst_active"),
        "settle_cycles": cycles("t_settle"),
        "init_cycles": cycles("t_init"),
        "init_to_dvalid_clocks": int(TIMING["init_to_dvalid_clocks"].value),
        "crossover_cycles": cycles("t_crossover"),
        "switch_cycles": cycles("t_switch"),
    }


@dataclass(frozen=True)
class Command:
    """One executed command: ``kind`` is ``"row"``, ``"clear"`` or ``"pulse"``; ``mode`` the
    row mode name or the pulse kind (``single``, ``dual``, ``quad``, ``global``)."""
    cycle: int
    kind: str
    blocks: tuple
    row: int | None = None
    mode: str | None = None


@dataclass
class _RowCycle:
    start: int
    rowmd: RowMode
    row: int | None
    comp: int
    held: tuple
    beats: list


class Dlpc410:
    """A DLPC410 with its DMD.

    Parameters
    ----------
    dmd : spec.facts.DmdType
    beats : int
        DCLK cycles per step (``dmd`` cycle): 1 at DCLK 200 MHz, 2 at 400 MHz.
    clock_hz : float
        The rate of the steps; the timing defaults are the facts at this rate
        (:func:`timing_cycles`).
    rst_active_cycles, settle_cycles, init_cycles, init_to_dvalid_clocks : int, optional
        Override the facts (tests use short ones).
    init_grace_cycles : int
        Cycles after INIT_ACTIVE falls in which the training pattern (DVALID included) may go on
        as during initialisation; commands are still forbidden. Default 0: DVALID high in the
        ``init_to_dvalid_clocks`` after the fall is a break from the first cycle.
    ecp2_cycles : int
        ECP2_FINISHED rises on this cycle.
    restart_at, restart_cycles, restart_ecp2_cycles, restart_grace_cycles : int, optional
        A restart mid-run (see the module's notes); ``restart_at`` None: none.
    strict_rst_active : bool
        No pulse at all while RST_ACTIVE is high (default), or only none of the same blocks.
    reading : str
        What the settle time forbids (a key of :data:`spec.facts.SETTLE_READINGS`): ``"ti"``
        (default), any change to a pulsed block's memory until ``settle_cycles`` after RST_ACTIVE
        falls; ``"paper"``, only the block's next pulse sooner than ``settle_cycles`` after its
        last (its memory may change once RST_ACTIVE falls).
    check_training : bool
        Require the training pattern during initialisation.
    keep_history : bool
        Record the mirror state at every pulse (what :class:`sim.models.camera_model.Camera` reads).
    ddc_version : int
        Value driven on DDC_VERSION.

    Attributes
    ----------
    memory : ndarray (rows, columns) uint8
        The DMD's SRAM, 0/1.
    mirrors : ndarray (rows, columns) uint8
        The state latched by each block's last clocking pulse.
    log : list of Command
    pulse_cycles : list of lists
        Per block, the cycles of its clocking pulses.
    history : list of lists
        Per block, ``(cycle, state)`` at every pulse (``state`` is the block's mirror array).
    arstz_rise : int or None
        Cycle ARSTZ went high; ``init_end`` the cycle INIT_ACTIVE fell.
    """

    def __init__(self, dmd, *, beats=1, clock_hz=200e6, rst_active_cycles=None, settle_cycles=None,
                 init_cycles=None, init_to_dvalid_clocks=None, init_grace_cycles=0, ecp2_cycles=4,
                 strict_rst_active=True, check_training=True, keep_history=True, ddc_version=0,
                 restart_at=None, restart_cycles=0, restart_ecp2_cycles=0, restart_grace_cycles=4, reading="ti"):
        if dmd.bits_per_dclk % 64:
            raise ValueError(f"{dmd.name}: {dmd.bits_per_dclk} bits per DCLK is not modelled")
        if dmd.dclk_per_row % beats:
            raise ValueError(f"{dmd.name}: {dmd.dclk_per_row} DCLK per row is not {beats} beats a cycle")
        facts = timing_cycles(clock_hz)
        self.dmd = dmd
        self.beats = beats
        self.clock_hz = clock_hz
        #: the facts at ``clock_hz`` in cycles (crossover and switching times for the camera)
        self.timing = facts
        given = {"rst_active_cycles": rst_active_cycles, "settle_cycles": settle_cycles,
                 "init_cycles": init_cycles, "init_to_dvalid_clocks": init_to_dvalid_clocks}
        for key, value in given.items():
            setattr(self, key, facts[key] if value is None else value)
        self.init_grace_cycles = init_grace_cycles
        self.ecp2_cycles = ecp2_cycles
        self.restart_at, self.restart_cycles = restart_at, restart_cycles
        self.restart_ecp2_cycles, self.restart_grace_cycles = restart_ecp2_cycles, restart_grace_cycles
        self.strict_rst_active = strict_rst_active
        self.reading = SETTLE_READINGS[reading]
        self.check_training = check_training
        self.keep_history = keep_history
        self.ddc_version = ddc_version
        self.words_per_beat = dmd.bits_per_dclk // 64
        self.buses = "abcd"[:dmd.buses]
        self.memory = np.zeros((dmd.rows, dmd.columns), np.uint8)
        self.mirrors = np.zeros_like(self.memory)
        self.log = []
        self.pulse_cycles = [[] for _ in range(dmd.blocks)]
        self.history = [[] for _ in range(dmd.blocks)]
        self.cycle = 0
        self.arstz_rise = None
        self.init_end = None
        self._arstz = 0
        self._edges = []                          # the last four training edges per bus
        self._last_pulse = [None] * dmd.blocks   # pulse cycle per block
        self._rst_until = -1                      # last cycle RST_ACTIVE is high
        self._reset_controller()

    # --- outputs -------------------------------------------------------------------------------

    def init_active(self, cycle=None):
        cycle = self.cycle if cycle is None else cycle
        return self.init_end is None or cycle < self.init_end or self._in_restart(cycle, 0, self.restart_cycles)

    def _in_restart(self, cycle, begin, end):
        """``cycle`` is between ``begin`` and ``end`` cycles after the restart began."""
        return self.restart_at is not None and self.restart_at + begin <= cycle < self.restart_at + end

    def _ignored(self, cycle):
        """The first cycles of a restart: the FPGA cannot have seen INIT_ACTIVE yet."""
        return self._in_restart(cycle, 0, self.restart_grace_cycles)

    def _initialising(self, cycle):
        """INIT_ACTIVE high, or within ``init_grace_cycles`` after it fell (the training
        pattern may still be on the pins while the FPGA's synchroniser catches up)."""
        return (self.init_end is None or cycle < self.init_end + self.init_grace_cycles
                or self._in_restart(cycle, 0, self.restart_cycles + self.init_grace_cycles))

    def _init_fell(self, cycle):
        """The cycle INIT_ACTIVE fell last, up to ``cycle``."""
        if self.restart_at is not None and cycle >= self.restart_at + self.restart_cycles:
            return self.restart_at + self.restart_cycles
        return self.init_end

    def outputs(self):
        """The controller's outputs on the current cycle."""
        return {
            "init_active": int(self.init_active()),
            "rst_active": int(self.cycle <= self._rst_until),
            "ecp2_finished": int(self.cycle >= self.ecp2_cycles
                                 and not self._in_restart(self.cycle, 0, self.restart_ecp2_cycles)),
            "dmd_type": 0b1111 if self.dmd.dmd_type_code is None else self.dmd.dmd_type_code,
            "ddc_version": self.ddc_version,
        }

    # --- the per-cycle interface ---------------------------------------------------------------

    def step(self, signals):
        """Consume one cycle of the FPGA's outputs; return the controller's outputs for the next."""
        c = self.cycle
        s = signals
        self._track_arstz(c, s.get("arstz", 0))
        if c == self.restart_at:
            self._restart(c)
        if self._ignored(c):
            pass
        elif self._initialising(c):
            self._init_cycle(c, s)
        else:
            self._framing(c, s)
        self.cycle = c + 1
        return self.outputs()

    def idle(self, count, signals=None):
        """``count`` cycles with DVALID low and ``signals`` (default: ARSTZ high) held; as
        :meth:`step` each time, faster once nothing but the idle gap can change."""
        s = {"arstz": 1} if signals is None else signals
        assert not s.get("dvalid", 0), "idle() is for DVALID low"
        while count:
            c = self.cycle
            if (self._arstz != s.get("arstz", 0) or self._initialising(c) or self._row
                    or c == self.restart_at or self._ignored(c)):
                self.step(s)
                count -= 1
                continue
            n = count if self.restart_at is None or c > self.restart_at else min(count, self.restart_at - c)
            if self._gap is not None:
                self._gap += n * self.beats
            self.cycle += n
            count -= n
        return self.outputs()

    def quiet(self):
        """True when a DVALID-low cycle with ARSTZ high can only lengthen the idle gap (past
        initialisation, no row cycle open): adapters then need read nothing else."""
        return (bool(self._arstz) and not self._initialising(self.cycle) and self._row is None
                and self.cycle != self.restart_at and not self._ignored(self.cycle))

    def quiet_outputs_until(self):
        """The first cycle after this one whose outputs differ from this cycle's if only idle
        cycles (DVALID low, ARSTZ high) come, or None if they never do."""
        changes = [self._rst_until + 1 if self.cycle <= self._rst_until else None,
                   self.ecp2_cycles if self.cycle < self.ecp2_cycles else None,
                   self.init_end if self.init_end is not None and self.cycle < self.init_end else None]
        if self.restart_at is not None:
            changes += [c for c in (self.restart_at, self.restart_at + self.restart_ecp2_cycles,
                                    self.restart_at + self.restart_cycles) if c > self.cycle]
        return min((c for c in changes if c is not None), default=None)

    def run(self, items):
        """Feed a sequence of per-cycle dicts and :class:`Idle` items (see the driver)."""
        for item in items:
            if isinstance(item, dict):
                self.step(item)
            else:
                self.idle(item.count, item.signals)
        return self.outputs()

    # --- initialisation ------------------------------------------------------------------------

    def _reset_controller(self):
        self._row = None            # the row cycle being received
        self._gap = None            # idle cycles since the last row cycle (None: none yet)
        self._pointer = None
        self._clear_busy = 0        # no-op row cycles a clear still occupies
        self._clearing = None       # the block being cleared

    def _track_arstz(self, c, arstz):
        if arstz and not self._arstz:
            self.arstz_rise = c
            self.init_end = max(c, self.ecp2_cycles) + self.init_cycles
        elif not arstz and self._arstz:
            self.arstz_rise = self.init_end = None
            self._restart(c)
        self._arstz = arstz

    def _restart(self, c):
        """ARSTZ fell, or the controller initialises again: the DMD's state is lost."""
        self.memory[:] = 0
        self.mirrors[:] = 0
        for b in range(self.dmd.blocks):
            self._record_state(c, b)
        self._reset_controller()
        self._edges = []

    def _init_cycle(self, c, s):
        rowmd, blkmd = s.get("rowmd", 0), s.get("blkmd", 0)
        if rowmd or blkmd:
            raise RuleBreak(RULES["init_command"], c,
                            f"ROWMD={rowmd:02b} BLKMD={blkmd:02b} while INIT_ACTIVE is high")
        mask = (1 << PINS_PER_BUS) - 1
        for e in range(2 * self.beats):
            edge = tuple(s.get(f"din_{b}", 0) >> (PINS_PER_BUS * e) & mask for b in self.buses)
            if self.check_training and self._arstz and len(self._edges) == 4 and self.init_active(c):
                self._check_training(c, edge)
            self._edges = (self._edges + [edge])[-4:]

    def _check_training(self, c, edge):
        """Every pin repeats ``0100`` over four edges: any four consecutive edges hold one 1 on
        each pin, and every edge repeats the one four edges before."""
        mask = (1 << PINS_PER_BUS) - 1
        window = self._edges[1:] + [edge]
        for i, bus in enumerate(self.buses):
            edges = [e[i] for e in window]
            two = 0
            for a in range(4):
                for b in range(a + 1, 4):
                    two |= edges[a] & edges[b]
            one = edges[0] | edges[1] | edges[2] | edges[3]
            bad = two | (~one & mask) | (edge[i] ^ self._edges[0][i])
            if bad:
                pin = (bad & -bad).bit_length() - 1
                raise RuleBreak(RULES["init_training"], c,
                                f"DIN_{bus.upper()}({pin}) does not repeat 0100 while INIT_ACTIVE is high")

    # --- row-cycle framing ---------------------------------------------------------------------

    def _framing(self, c, s):
        """One cycle's ``beats`` DCLK cycles, each a beat of a row cycle or an idle DCLK cycle."""
        dvalid = s.get("dvalid", 0)
        pair = (1 << (2 * PINS_PER_BUS)) - 1
        for b in range(self.beats):
            if not dvalid >> (2 * b) & 1:
                if self._row is not None:
                    raise RuleBreak(RULES["row_cycle"], c,
                                    f"DVALID fell after {len(self._row.beats)} of {self.dmd.dclk_per_row} "
                                    f"DCLK cycles of the row cycle from cycle {self._row.start}")
                if self._gap is not None:
                    self._gap += 1
                continue
            if self._row is None:
                self._start_row(c, s)
            elif _held(s) != self._row.held:
                changed = [n for n, x, y in zip(_HELD, _held(s), self._row.held, strict=True) if x != y]
                raise RuleBreak(RULES["row_hold"], c,
                                f"{', '.join(changed).upper()} changed in DCLK cycle {len(self._row.beats) + 1} "
                                f"of the row cycle from cycle {self._row.start}")
            self._row.beats.append([s.get(f"din_{bus}", 0) >> (2 * PINS_PER_BUS * b) & pair for bus in self.buses])
            if len(self._row.beats) == self.dmd.dclk_per_row:
                self._end_row(self._row)
                self._row = None
                self._gap = 0

    def _start_row(self, c, s):
        fell = self._init_fell(c)
        if c < fell + self.init_to_dvalid_clocks:
            raise RuleBreak(RULES["init_dvalid"], c,
                            f"DVALID high {c - fell} clocks after INIT_ACTIVE fell, "
                            f"needs {self.init_to_dvalid_clocks}")
        if self._gap is not None and self._gap % 2:
            raise RuleBreak(RULES["dvalid_gap"], c, f"DVALID low for {self._gap} cycles, must be even")
        rowmd = RowMode(s.get("rowmd", 0))
        blkmd = BlockMode(s.get("blkmd", 0))
        blkad = s.get("blkad", 0)
        rst2blkz = s.get("rst2blkz", _DEFAULTS["rst2blkz"])
        row = self._row_target(c, rowmd, s.get("rowad", 0), s.get("ns_flip", 0))
        if self._clear_busy:
            self._check_clear_busy(c, rowmd, blkmd, blkad, rst2blkz)
        if blkmd == BlockMode.CLEAR:
            self._clear(c, blkad, rowmd)
        elif blkmd != BlockMode.NOOP:
            self._pulse(c, blkmd, blkad, rst2blkz)
        if row is not None:
            self._check_settle(c, self.dmd.block_of_row(row), f"row {row}", "written")
        self._row = _RowCycle(c, rowmd, row, s.get("comp_data", 0), _held(s), [])

    def _end_row(self, rc):
        if rc.row is None:
            return
        words = np.array([word for beat in rc.beats for word in self._beat_words(beat)], dtype="<u8")
        bits = np.unpackbits(words.view(np.uint8), bitorder="little")
        self.memory[rc.row] = bits ^ 1 if rc.comp else bits
        self.log.append(Command(rc.start, "row", (self.dmd.block_of_row(rc.row),), rc.row, rc.rowmd.name))

    def _beat_words(self, pins):
        """One beat's pins (packed DinPairs, bus order) -> its words; the second word of a
        four-bus DMD travels on C/D as the first does on A/B (:mod:`gateware.dlpc410.beat`)."""
        mask = (1 << PINS_PER_BUS) - 1
        words = []
        for i in range(self.words_per_beat):
            a, b = pins[2 * i], pins[2 * i + 1]
            words.append(lanes_to_word({("A", "rise"): a & mask, ("A", "fall"): a >> PINS_PER_BUS,
                                        ("B", "rise"): b & mask, ("B", "fall"): b >> PINS_PER_BUS}))
        return words

    # --- row addressing ------------------------------------------------------------------------

    def _row_target(self, c, rowmd, rowad, ns_flip):
        """The row a row cycle writes (None for a no-op); moves the pointer."""
        rows = self.dmd.rows
        if rowmd == RowMode.NOOP:
            return None
        if rowmd == RowMode.ADDRESSED:
            if rowad >= rows:
                raise RuleBreak(RULES["row_address"], c, f"ROWAD={rowad}, the array has rows 0..{rows - 1}")
            self._pointer = rowad
        elif rowmd == RowMode.FIRST:
            self._pointer = rows - 1 if ns_flip else 0
        else:
            if self._pointer is None:
                raise RuleBreak(RULES["row_pointer"], c,
                                "ROWMD=01 before the pointer was set (ROWMD 10 or 11)")
            step = -1 if ns_flip else 1
            if not 0 <= self._pointer + step < rows:
                raise RuleBreak(RULES["row_pointer"], c,
                                f"ROWMD=01 would move the pointer from row {self._pointer} past the array "
                                f"(0..{rows - 1}); it does not wrap")
            self._pointer += step
        return self._pointer

    # --- block commands ------------------------------------------------------------------------

    def _blocks(self, c, blkmd, blkad, rst2blkz):
        """(kind, blocks) a block command addresses."""
        n = self.dmd.blocks
        if blkmd in (BlockMode.CLEAR, BlockMode.RESET):
            if blkad >= n:
                raise RuleBreak(RULES["block_address"], c, f"BLKAD={blkad}, the DMD has blocks 0..{n - 1}")
            return "single", (blkad,)
        if blkad & 0b1000:
            if blkad & 0b0100:
                raise RuleBreak(RULES["block_address"], c,
                                f"BLKMD=11 with BLKAD={blkad:04b} (global is 10xx)")
            return "global", tuple(range(n))
        if rst2blkz:
            if blkad & 1:
                raise RuleBreak(RULES["block_address"], c, f"quad pulse with BLKAD={blkad:04b}, must be 0qq0")
            kind, first, size = "quad", 4 * (blkad >> 1), 4
        else:
            kind, first, size = "dual", 2 * blkad, 2
        blocks = tuple(b for b in range(first, first + size) if b < n)
        if not blocks:
            raise RuleBreak(RULES["block_address"], c,
                            f"{kind} pulse of blocks {first}.. beyond block {n - 1}")
        return kind, blocks

    def _pulse(self, c, blkmd, blkad, rst2blkz):
        kind, blocks = self._blocks(c, blkmd, blkad, rst2blkz)
        self._check_rst_active(c, blocks)
        if self.reading.flip:
            self._check_flip(c, blocks)
        for b in blocks:
            self._last_pulse[b] = c
            self.pulse_cycles[b].append(c)
            rows = self._block_rows(b)
            self.mirrors[rows] = self.memory[rows]
            self._record_state(c, b)
        self._rst_until = max(self._rst_until, c + self.rst_active_cycles)
        self.log.append(Command(c, "pulse", blocks, None, kind))

    def _clear(self, c, block, rowmd):
        _kind, (block,) = self._blocks(c, BlockMode.CLEAR, block, 1)
        if rowmd != RowMode.NOOP:
            raise RuleBreak(RULES["clear_overlap"], c,
                            f"clear of block {block} in a row cycle with ROWMD={rowmd.value:02b}")
        self._check_settle(c, block, "block", "cleared")
        self.memory[self._block_rows(block)] = 0
        self._clear_busy = self.dmd.clear_row_cycles - 1
        self._clearing = block
        self.log.append(Command(c, "clear", (block,)))

    def _check_clear_busy(self, c, rowmd, blkmd, blkad, rst2blkz):
        """A row cycle inside a clear's no-op rows (1080p: clear + 2 no-op rows)."""
        what = None
        if rowmd != RowMode.NOOP:
            what = f"a row load (ROWMD={rowmd.value:02b})"
        elif blkmd == BlockMode.CLEAR:
            what = "another clear"
        elif blkmd != BlockMode.NOOP and self._clearing in self._blocks(c, blkmd, blkad, rst2blkz)[1]:
            what = "a pulse of the block"
        if what:
            used = self.dmd.clear_row_cycles - self._clear_busy
            raise RuleBreak(RULES["clear_overlap"], c,
                            f"{what} in row cycle {used + 1} of {self.dmd.clear_row_cycles} "
                            f"of the clear of block {self._clearing}")
        self._clear_busy -= 1

    def _check_rst_active(self, c, blocks):
        if self.strict_rst_active:
            if c <= self._rst_until:
                raise RuleBreak(RULES["rst_active"], c,
                                f"pulse of blocks {list(blocks)} while RST_ACTIVE is high "
                                f"(until cycle {self._rst_until})")
            return
        for b in blocks:
            p = self._last_pulse[b]
            if p is not None and c <= p + self.rst_active_cycles:
                raise RuleBreak(RULES["rst_active"], c,
                                f"pulse of block {b} {c - p} cycles after its own pulse, while its "
                                f"RST_ACTIVE is high ({self.rst_active_cycles} cycles)")

    def _check_flip(self, c, blocks):
        for b in blocks:
            p = self._last_pulse[b]
            if p is not None and c < p + self.settle_cycles:
                raise RuleBreak(RULES["flip"], c, f"pulse of block {b} {c - p} cycles after its last, "
                                                  f"needs {self.settle_cycles}")

    def _check_settle(self, c, block, what, verb):
        p = self._last_pulse[block]
        if p is None:
            return
        fall = p + self.rst_active_cycles + 1
        if c < fall + (self.settle_cycles if self.reading.frozen else 0):
            when = (f"{c - fall} cycles after RST_ACTIVE fell" if c >= fall
                    else f"{c - p} cycles after its pulse, while RST_ACTIVE is high")
            raise RuleBreak(RULES["settle"], c,
                            f"{what} of block {block} {verb} {when}, needs {self.settle_cycles}")

    # --- mirror state over time ----------------------------------------------------------------

    def mirrors_at(self, cycle, motion_cycles=None):
        """The state the mirrors have *settled* in at ``cycle``: per block, the state latched by
        its last pulse at least ``motion_cycles`` (default the switching time) before; mirrors
        still moving show the state they leave. Needs ``keep_history``."""
        motion = self.timing["switch_cycles"] if motion_cycles is None else motion_cycles
        rpb = self.dmd.rows_per_block
        out = np.zeros_like(self.mirrors)
        for b, hist in enumerate(self.history):
            done = [state for c, state in hist if c + motion <= cycle]
            if done:
                out[b * rpb:(b + 1) * rpb] = done[-1]
        return out

    # --- the log as the schedule model speaks it -----------------------------------------------

    def commands(self, shift=0):
        """:attr:`log` as the command tuples of :mod:`spec.schedule`:
        ``(cycle + shift, "row", row)``, ``(.., "clear", block)`` and ``(.., "pulse", blocks)``,
        in cycle order (``shift`` maps model cycles to the sequencer's time base)."""
        out = []
        for cmd in sorted(self.log, key=lambda cmd: cmd.cycle):
            arg = {"row": cmd.row, "clear": cmd.blocks[0], "pulse": cmd.blocks}[cmd.kind]
            out.append((cmd.cycle + shift, cmd.kind, arg))
        return out

    def block_command(self, blkmd, blkad, rst2blkz):
        """``(kind, blocks)`` a block command with these pins addresses (RuleBreak if none)."""
        return self._blocks(self.cycle, BlockMode(blkmd), blkad, rst2blkz)

    # --- helpers -------------------------------------------------------------------------------

    def _block_rows(self, block):
        rpb = self.dmd.rows_per_block
        return slice(block * rpb, (block + 1) * rpb)

    def _record_state(self, c, block):
        if self.keep_history:
            self.history[block].append((c, self.mirrors[self._block_rows(block)].copy()))


# --- adapters ------------------------------------------------------------------------------------

def amaranth_process(model, iface, *, domain="sync"):
    """An async process for :meth:`amaranth.sim.Simulator.add_process` that steps ``model`` on
    every clock edge of ``domain`` with the values ``iface`` (a DLPC410 interface object, e.g.
    ``dut.dlpc``) held before the edge, and drives the controller's outputs into it."""
    from amaranth.hdl import Value

    names = [n for n in INPUTS if hasattr(iface, n)]
    values = [Value.cast(getattr(iface, n)) for n in names]
    outs = [n for n in OUTPUTS if hasattr(iface, n)]

    def drive(ctx, levels):
        for n in outs:
            ctx.set(getattr(iface, n), levels[n])

    async def process(ctx):
        drive(ctx, model.outputs())
        async for _clk, _rst, *sampled in ctx.tick(domain).sample(*values):
            drive(ctx, model.step(dict(zip(names, sampled, strict=True))))

    return process


#: What a quiet cycle's pins amount to (:meth:`CocotbAdapter._sample`).
_QUIET = {"dvalid": 0, "arstz": 1}


class CocotbAdapter:
    """Steps ``model`` on each rising edge of ``clock`` from the signals of a cocotb ``dut``.

    A flattened interface member ``name`` is the Verilog signal ``prefix + name`` (Amaranth
    names ``dlpc.din_a`` ``dlpc__din_a``); ``names`` overrides single members
    (``{"arstz": "dmd_arstz"}``). Members absent from the DUT are left out (inputs read as
    their reset values, outputs are not driven).

    ``await adapter.run()`` runs until the test ends and raises :class:`RuleBreak` on a break.
    Each cycle it samples the pins mid-cycle (falling edge of ``clock``, where registered
    outputs are stable) and drives the controller's outputs after the next rising edge, as
    :func:`amaranth_process` does.

    With ``rest``, quiet stretches (:meth:`Dlpc410.quiet`, DVALID low and ARSTZ high) in which
    the controller's outputs stay as they are (:meth:`Dlpc410.quiet_outputs_until`) are not
    stepped cycle by cycle: the adapter rests until DVALID or ARSTZ changes (on a rising edge
    of ``clock``) and then gives the model the cycles it rested as :meth:`Dlpc410.idle`, which
    is stepping each of them. Meanwhile the model's ``cycle`` lags behind the simulation: for
    testbenches that read the model's commands (``log``, the mirror history), not its cycle.
    """

    def __init__(self, model, dut, clock, *, prefix="dlpc__", names=None, rest=False):
        self.model, self.clock, self.rest = model, clock, rest
        names = names or {}

        def handle(member):
            return getattr(dut, names.get(member, prefix + member), None)

        self.inputs = [(n, h) for n in INPUTS if (h := handle(n)) is not None]
        self.outputs = [(n, h) for n in OUTPUTS if (h := handle(n)) is not None]
        self._dvalid, self._arstz = handle("dvalid"), handle("arstz")
        self._driven = {}
        self._changed = None         # set when DVALID or ARSTZ changes, once the adapter rests

    def _drive(self, levels):
        for n, h in self.outputs:
            if self._driven.get(n) != levels[n]:
                h.value = self._driven[n] = levels[n]

    def _sample(self):
        # on quiet cycles (Dlpc410.quiet) only DVALID and ARSTZ matter: two reads, not fifteen
        if self._dvalid is not None and self._arstz is not None and self.model.quiet():
            dvalid, arstz = int(self._dvalid.value), int(self._arstz.value)
            if not dvalid and arstz:
                return dict(_QUIET)
        return {n: int(h.value) for n, h in self.inputs}

    async def run(self):
        from cocotb.triggers import FallingEdge, RisingEdge
        from cocotb.utils import get_sim_time

        falling, rising = FallingEdge(self.clock), RisingEdge(self.clock)
        self._drive(self.model.outputs())
        last = period = None
        while True:
            await falling
            sampled = self._sample()
            await rising
            self._drive(self.model.step(sampled))
            if not self.rest:
                continue
            now = get_sim_time("step")
            if period is None:       # the clock's period, from its first two rising edges
                period, last = (None if last is None else now - last), now
            elif sampled == _QUIET and self.model.quiet():
                await self._rest(now, period)

    async def _rest(self, edge, period):
        """Rest from the rising edge at ``edge`` (steps) while the model is quiet and its outputs
        stay as they are; on return, the next falling edge samples the next cycle the model has
        not had."""
        import cocotb
        from cocotb.triggers import Event
        from cocotb.utils import get_sim_time

        if self._dvalid is None or self._arstz is None or self.model.quiet_outputs_until() is not None:
            return
        if self._changed is None:
            # one waiter per pin for the whole run: the adapter itself waits on a single event,
            # so that cancelling it stays immediate
            self._changed = Event()
            for pin in (self._dvalid, self._arstz):
                cocotb.start_soon(self._watch(pin))
        self._changed.clear()
        await self._changed.wait()
        rested, phase = divmod(get_sim_time("step") - edge, period)
        assert phase == 0, "DVALID or ARSTZ changed between rising edges of the clock"
        if rested:
            self.model.idle(rested, dict(_QUIET))

    async def _watch(self, pin):
        while True:
            await pin.value_change
            self._changed.set()
