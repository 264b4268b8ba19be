"""The tiled display rig: a sync master and several projector boards, each on its own crystal,
in one Verilator simulation.

A tiled display shows one scene on several DMDs, each driven by its own board with its own
oscillator; a sync master pulses every board once a frame. This rig is that system in Verilog:

* the sync master (:class:`gateware.sync.master.SyncMaster`, its generated Verilog) on an
  oscillator of its own, in PERIODIC mode: one pulse per frame period of its clock, refused
  (and counted) while a board is not ready;
* ``boards`` boards (:class:`Board`), each the sequencer with its store stand-in
  (:class:`sim.tb.plane_source.SourcedSequencer`, its generated Verilog) in SYNC mode, on an
  oscillator (``board_clock.v``) with its own frequency error, drift ramp and jitter; each with
  its own DLPC410 responder, pin recorder and a recorder of its clocking pulses' times
  (``trace_recorder.v`` with time stamps); its ready line goes back to the master; its clock
  loop (:class:`gateware.sync.clock_trim.ClockTrim`, generated Verilog) pulls its oscillator
  when the registers' ``period`` is set (:func:`run_tiled` ``trim``).

Every clock is a Verilog oscillator (Verilator's ``--timing``): the testbench
(:mod:`sim.tb.tiled_rig_tb`) only sets the registers, arms the master and waits for the pulses.
:func:`run_tiled` writes the tables, runs it and returns the pulse times
(:class:`TiledRun`); each board's pins can be replayed through the rule-checking DLPC410 model
(:meth:`TiledRun.board_run`).
"""

import json
import math
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
from amaranth import Cat, ClockSignal, Const, DomainRenamer, Instance, Module, ResetSignal, Signal, signed
from amaranth.lib import data, wiring
from amaranth.lib.wiring import In, Out

from gateware.compose import members
from gateware.dlpc410.sequencer import Status
from gateware.registers import Registers, TriggerMode
from gateware.sync.clock_trim import ClockTrim
from gateware.sync.master import SyncMaster
from sim.harness import cocotb_run
from sim.harness.layout import pack
from sim.harness.paths import ROOT, build_dir, slug
from sim.models import trace
from sim.models.camera_model import Camera, to_lsb
from sim.rigs.fast_system_rig import dlpc410_side, power_on_reset
from sim.rigs.seq_rig import SOURCES as RIG_SOURCES
from sim.rigs.seq_rig import Timing, analyse, file_table, responder_timing, rig_layout, write_tables
from sim.tb.plane_source import TABLES, SourcedSequencer, table_depths
from sim.tb.seq_sim import CAMERA_DELAY, CAMERA_RAMP, dlpc410_for

__all__ = ["TiledRig", "Board", "Oscillator", "TiledRun", "run_tiled", "board_plusargs", "TOPLEVEL", "SOURCES",
           "MASTER_PERIOD_FS", "BOARD_PERIOD_FS", "VERILATOR_TIMING", "TRIM_PPB", "LoopState", "tiles", "master_period"]

TOPLEVEL = "tiled_rig"
SOURCES = [*RIG_SOURCES, ROOT / "sim" / "hdl" / "board_clock.v"]
#: Verilator's flags for delays in Verilog (the oscillators): its timing support, built with
#: the C++20 coroutines it runs on.
VERILATOR_TIMING = ["--timing", "-CFLAGS", "-fcoroutines -std=c++20"]
#: Nominal periods: the master's 125 MHz, the boards' ``dmd`` clock at 200 MHz.
MASTER_PERIOD_FS = 8_000_000
BOARD_PERIOD_FS = 5_000_000
#: The pull of one step of a board's trim word (its VCXO and DAC), in ppb: +-131 ppm with a
#: term of the loop's 15 bits.
TRIM_PPB = 8


def tiles(dmd, boards, row_step=1):
    """One scene across ``boards`` DMDs side by side, split in their tiles: a ramp holding every
    grey level across the whole width, shifted by ``row_step`` levels a row."""
    rows, columns = np.indices((dmd.rows, dmd.columns * boards))
    scene = ((columns * 255) // (dmd.columns * boards - 1) + row_step * rows) & 255
    return [scene[:, i * dmd.columns:(i + 1) * dmd.columns].astype(np.uint8) for i in range(boards)]


def master_period(frame_cycles):
    """The master's period (its cycles) for frames of ``frame_cycles`` board cycles: the slowest
    board's frame and a margin to load the next, whole board cycles (for the clock loops)."""
    period = int(frame_cycles * BOARD_PERIOD_FS / MASTER_PERIOD_FS * 1.001) + 64
    return period + -period % (BOARD_PERIOD_FS // math.gcd(BOARD_PERIOD_FS, MASTER_PERIOD_FS))


def board_plusargs(index):
    """The plusarg names of board ``index``: its tables, pin trace, pulse times and clock."""
    return {**{name: f"TILE{index}_{name.upper()}" for name in TABLES},
            "pins": f"TILE{index}_PINS", "pulses": f"TILE{index}_PULSES", "clock": f"TILE{index}_CLK"}


#: The master's: its clock, and the times of its sync pulses.
MASTER_PLUSARGS = {"clock": "MASTER_CLK", "pulses": "MASTER_PULSES"}


def _oscillator(m, plusarg, domain, trim=0):
    """Domain ``domain`` on a ``board_clock.v`` named by ``plusarg`` and pulled by ``trim``, out
    of reset after :data:`sim.rigs.fast_system_rig.RESET_CYCLES` of its cycles."""
    clk = Signal(name=f"{domain}_clk")
    m.submodules[f"{domain}_oscillator"] = Instance("board_clock", p_PLUSARG=plusarg, i_trim=trim, o_clk=clk)
    power_on_reset(m, domain, clk)


def _pulse_times(m, domain, plusarg, value, strobe, flush):
    """``trace_recorder.v`` writing the time (ps), cycle and ``value`` of each cycle of
    ``domain`` with ``strobe`` high to the file of plusarg ``plusarg``."""
    m.submodules[f"{domain}_times"] = Instance(
        "trace_recorder", p_WIDTH=len(value), p_PLUSARG=plusarg, p_ON_CHANGE=0, p_STAMP_PS=1,
        i_clk=ClockSignal(domain), i_rst=ResetSignal(domain), i_value=value, i_always_record=strobe, i_flush=flush)


class Board(wiring.Component):
    """One projector board of the tiled display, on its own oscillator (domain ``b<index>``).

    Parameters
    ----------
    dmd : DmdType
    index : int
        The board's number: its domain and plusargs (:func:`board_plusargs`).
    beats, store_words : int
        As the sequencer's.

    Members
    -------
    regs : In(Registers)
        The sequencer's registers (SYNC trigger mode for a tiled display).
    timing : In(Timing)
        The DLPC410 responder's cycle counts.
    sync_in : In(1)
        The master's sync line (asynchronous).
    ready : Out(1)
        The sequencer's ready line: a pulse now would be obeyed at once.
    flush : In(1)
        Writes the recorders' buffered lines to their files.
    status : Out(Status)
        The sequencer's counters.
    trim, locked, pulses, slips : Out
        The clock's loop (:class:`~gateware.sync.clock_trim.ClockTrim`: on while the registers'
        ``period``, the sync period in nominal cycles, is not 0): its control word, lock, the
        pulses it saw and its slips.
    """

    def __init__(self, dmd, index, *, beats=1, store_words=1):
        self._dmd, self._index, self._beats, self._store_words = dmd, index, beats, store_words
        self._core = SourcedSequencer(dmd, beats=beats, store_words=store_words)
        self._trim = ClockTrim()
        super().__init__({
            **members(self._core, ("regs", "sync_in", "ready", "status")),
            "timing": In(Timing),
            "flush": In(1),
            **members(self._trim, ("trim", "locked", "pulses", "slips")),
        })

    def elaborate(self, platform):
        m = Module()
        dmd, domain, names = self._dmd, f"b{self._index}", board_plusargs(self._index)
        core, trim = self._core, self._trim
        _oscillator(m, names["clock"], domain, trim.trim)
        m.submodules.core = DomainRenamer(domain)(core)
        m.submodules.clock_trim = DomainRenamer(domain)(trim)
        m.d.comb += [
            core.regs.eq(self.regs), core.sync_in.eq(self.sync_in), self.ready.eq(core.ready),
            self.status.eq(core.status), core.release.ready.eq(1),
            trim.sync_in.eq(self.sync_in), trim.now.eq(core.status.now[:16]), trim.period.eq(self.regs.period),
            self.trim.eq(trim.trim), self.locked.eq(trim.locked), self.pulses.eq(trim.pulses),
            self.slips.eq(trim.slips),
        ]
        depths = table_depths(dmd, self._store_words)
        for name in TABLES:
            file_table(m, name, getattr(core, name), depths[name], plusarg=names[name])
        pins = core.pins
        running = Signal()
        m.d.comb += running.eq(core.status.now != 0)
        dlpc410_side(m, dmd, pins, flush=self.flush, domain=domain, layout=rig_layout(dmd.buses, self._beats),
                     always=core.release.valid, plusarg=names["pins"],
                     extra={"trigger_in": core.trigger_in, "sync_out": core.sync_out,
                            "camera_out": core.camera_out, "running": running,
                            "release_valid": core.release.valid, "release_slot": core.release.payload,
                            "ready": core.ready},
                     **{name: getattr(self.timing, name) for name, _ in Timing.as_shape()})
        # a clocking pulse: BLKMD reset (one block) or multi-block (dual, quad, global); with the
        # block command, whether the clock loop was locked then
        _pulse_times(m, domain, names["pulses"], Cat(pins.blkad, pins.blkmd, pins.rst2blkz, trim.locked),
                     pins.blkmd.as_value()[1], self.flush)
        return m


class LoopState(data.Struct):
    """A board's clock loop, as the rig reports it."""
    trim: signed(16)
    locked: 1
    pulses: 32
    slips: 32


class TiledRig(wiring.Component):
    """A sync master and ``boards`` :class:`Board` s, every one on its own oscillator.

    Members
    -------
    regs, timing : In
        Every board's registers and responder timing.
    mode, period, min_period, width, run : In
        The master's (:class:`~gateware.sync.master.SyncMaster`); ``period`` in master cycles.
    pulses, not_ready, early : Out(32)
        The master's counters.
    ready : Out(boards)
        The boards' ready lines.
    status : Out(ArrayLayout(Status, boards))
        The boards' counters.
    loops : Out(ArrayLayout(LoopState, boards))
        The boards' clock loops.
    flush : In(1)
        Writes every recorder's buffered lines to its file.
    """

    def __init__(self, dmd, boards=4, *, beats=1, store_words=1):
        self._dmd, self._boards, self._beats, self._store_words = dmd, boards, beats, store_words
        self._master = SyncMaster(boards)
        super().__init__({
            "regs": In(Registers),
            "timing": In(Timing),
            **members(self._master, ("mode", "period", "min_period", "width", "run", "pulses", "not_ready",
                                     "early")),
            "ready": Out(boards),
            "status": Out(data.ArrayLayout(Status, boards)),
            "loops": Out(data.ArrayLayout(LoopState, boards)),
            "flush": In(1),
        })

    def elaborate(self, platform):
        m = Module()
        _oscillator(m, MASTER_PLUSARGS["clock"], "master")
        master = self._master
        m.submodules.master = DomainRenamer("master")(master)
        for name in ("mode", "period", "min_period", "width", "run"):
            m.d.comb += getattr(master, name).eq(getattr(self, name))
        for name in ("pulses", "not_ready", "early"):
            m.d.comb += getattr(self, name).eq(getattr(master, name))
        m.d.comb += [master.trigger_in.eq(0), master.soft.eq(0), master.ready.eq(self.ready)]
        last = Signal()
        m.d.master += last.eq(master.sync_out[0])
        _pulse_times(m, "master", MASTER_PLUSARGS["pulses"], Const(1, 1), master.sync_out[0] & ~last, self.flush)
        for i in range(self._boards):
            board = m.submodules[f"board{i}"] = Board(self._dmd, i, beats=self._beats, store_words=self._store_words)
            m.d.comb += [
                board.regs.eq(self.regs), board.timing.eq(self.timing), board.flush.eq(self.flush),
                board.sync_in.eq(master.sync_out[i]), self.ready[i].eq(board.ready),
                self.status[i].eq(board.status), self.loops[i].trim.eq(board.trim),
                self.loops[i].locked.eq(board.locked), self.loops[i].pulses.eq(board.pulses),
                self.loops[i].slips.eq(board.slips),
            ]
        return m


# --- running it ----------------------------------------------------------------------------------

@dataclass(frozen=True)
class Oscillator:
    """A crystal as ``board_clock.v`` models it: ``ppm`` off its nominal frequency at time 0
    (positive: fast), drifting by ``ramp_ppm_per_s`` (a temperature change), each edge up to
    ``jitter_ps`` either side of its ideal time."""
    ppm: float = 0.0
    ramp_ppm_per_s: float = 0.0
    jitter_ps: float = 0.0
    seed: int = 1

    def plusargs(self, name, period_fs):
        return [f"+{name}_PERIOD_FS={period_fs}", f"+{name}_PPB={round(self.ppm * 1000)}",
                f"+{name}_TRIM_PPB={TRIM_PPB}",
                f"+{name}_RAMP_PPB={round(self.ramp_ppm_per_s)}",           # ppb per ms
                f"+{name}_JITTER_FS={round(self.jitter_ps * 1000)}", f"+{name}_SEED={self.seed}"]

    def error(self, t_s):
        """The frequency error (a fraction) at time ``t_s``."""
        return (self.ppm + self.ramp_ppm_per_s * t_s) * 1e-6


@dataclass
class TiledRun:
    """What :func:`run_tiled` recorded: the master's sync pulse times ``syncs`` (ps) and per
    board its clocking pulses ``pulses[i]`` (arrays of time in ps, cycle, and ``value``: the
    block command, its clock loop's lock in bit 7), its counters ``status[i]`` and its clock
    loop's state ``loops[i]`` at the end (:class:`LoopState`, the trim word as unsigned bits),
    the master's ``counts``; the report's ``wall_s``."""
    syncs: np.ndarray
    pulses: list
    status: list
    loops: list
    counts: dict
    wall_s: float
    traces: list = field(default_factory=list)
    models: list = field(default_factory=list)

    def frame_pulses(self):
        """Per board, per sync pulse ``k`` (a frame), the times (ps) of the board's clocking
        pulses between sync ``k`` and sync ``k + 1``: ``[board][k] -> array``."""
        out = []
        for times, _cycles, _values in self.pulses:
            frame = np.searchsorted(self.syncs, times, side="right") - 1
            out.append([times[frame == k] for k in range(len(self.syncs))])
        return out

    def locked_from(self):
        """The first frame from which every board's clock loop stayed locked (None: never)."""
        first = 0
        for times, _cycles, values in self.pulses:
            unlocked = times[(values >> 7 & 1) == 0]
            if len(unlocked) == len(times):
                return None
            if len(unlocked):
                first = max(first, int(np.searchsorted(self.syncs, unlocked[-1], side="right")))
        return first

    def spreads(self):
        """Per frame and plane (the j-th clocking pulse after the sync), the latest board's pulse
        less the earliest's, in ns: ``(frames, pulses per frame)``, for the frames every board
        played whole (as many pulses as the first board's first frame)."""
        per_board = self.frame_pulses()
        count = len(per_board[0][0])
        rows = []
        for k in range(len(self.syncs)):
            frames = [board[k] for board in per_board]
            if count and all(len(f) == count for f in frames):
                stacked = np.stack(frames)
                rows.append((stacked.max(axis=0) - stacked.min(axis=0)) / 1000)
        return np.array(rows)

    def board_run(self, index, dmd):
        """Board ``index``'s pins replayed through the rule-checking DLPC410 model (raises on a
        broken rule): the :class:`sim.tb.seq_sim.Run`."""
        assert self.traces, "run without pin traces"
        return analyse(self.models[index], trace.read(self.traces[index]), dmd)

    def rate_ppm(self, index, t0_ps=0, t1_ps=None):
        """Board ``index``'s frequency error (ppm) measured from its pulses between ``t0_ps`` and
        ``t1_ps`` (default: all of them)."""
        times, cycles, _ = self.pulses[index]
        inside = (times >= t0_ps) & (times < (np.inf if t1_ps is None else t1_ps))
        t, c = times[inside], cycles[inside]
        return (BOARD_PERIOD_FS * (c[-1] - c[0]) / (1000 * (t[-1] - t[0])) - 1) * 1e6

    def rates_ppm(self, first, last):
        """Every board's :meth:`rate_ppm` over frames ``first..last - 1``."""
        end = self.syncs[last] if last < len(self.syncs) else None
        return [self.rate_ppm(i, self.syncs[first], end) for i in range(len(self.pulses))]

    def cycle_at(self, index, t_ps):
        """Board ``index``'s cycle (a fraction) at time ``t_ps``: between its pulses by their
        times and cycles (its clock's rate is constant to well under a ppm over a frame)."""
        times, cycles, _ = self.pulses[index]
        return float(np.interp(t_ps, times, cycles, left=np.nan, right=np.nan))

    def light(self, index, board_run, t0_ps, t1_ps, lsb_cycles):
        """What a camera integrating from ``t0_ps`` to ``t1_ps`` sees of board ``index``
        (``board_run``: its :meth:`board_run`), in units of a least significant plane of the
        nominal clock: the light counted in the board's cycles, scaled by its measured period."""
        c0, c1 = self.cycle_at(index, t0_ps), self.cycle_at(index, t1_ps)
        assert not np.isnan(c0) and not np.isnan(c1), "the window must lie between the board's pulses"
        camera = Camera(board_run.model, ramp_cycles=CAMERA_RAMP, delay_cycles=CAMERA_DELAY, visible=False)
        period_fs = 1000 * (t1_ps - t0_ps) / (c1 - c0)
        return to_lsb(camera.image(round(c0), round(c1)), lsb_cycles) * period_fs / BOARD_PERIOD_FS


def _read_times(path):
    lines = Path(path).read_text().split()
    values = np.array(lines, dtype=object).reshape(-1, 3) if lines else np.zeros((0, 3), dtype=object)
    return (np.array([int(v) for v in values[:, 0]], dtype=np.int64),
            np.array([int(v) for v in values[:, 1]], dtype=np.int64),
            np.array([int(v, 16) for v in values[:, 2]], dtype=np.int64))


def run_tiled(dmd, params, images, *, oscillators, master=Oscillator(), frames, name, master_period_cycles,
              depth=8, width=4, traces=True, trim=False, store_words=1, max_sim_s=None, offered=None):
    """Run the tiled rig: one board per image of ``images`` (8-bit images of ``dmd``'s size),
    each showing its image's ``depth`` most significant planes as a frame again at every sync
    pulse, under ``params`` (a
    :class:`spec.schedule.Params`; the trigger becomes SYNC); board ``i`` on ``oscillators[i]``,
    the master on ``master``, pulsing every ``master_period_cycles`` of its cycles (``width``
    cycles long) until it has sent ``frames`` pulses. ``traces``: record every board's pins (for
    :meth:`TiledRun.board_run`); without, only the pulse times. ``trim``: every board's clock
    loop on (the registers' ``period`` set to the master's period in nominal board cycles, which
    must be whole); ``store_words``: 64-bit words a transfer from each board's store stand-in.
    ``offered``: per board the frame table of its store stand-in (the frames of
    :func:`sim.tb.plane_source.contents`: a stored sequence, shown a frame a sync pulse, with
    each entry's settings), ``images[i]`` then ``{slot: image}``; default: the image in slot 0,
    shown again at every pulse. Returns the :class:`TiledRun`."""
    boards = len(images)
    assert len(oscillators) == boards
    sync_fs = master_period_cycles * MASTER_PERIOD_FS
    assert not trim or sync_fs % BOARD_PERIOD_FS == 0, "the sync period must be whole board cycles"
    p = replace(params, trigger=TriggerMode.SYNC, period=sync_fs // BOARD_PERIOD_FS if trim else 0)
    model = dlpc410_for(dmd, p)
    directory = build_dir("tiled_rig", slug(name))
    plusargs, trace_files, pulse_files = [], [], []
    for i, image in enumerate(images):
        names = board_plusargs(i)
        frames_i, given = (offered[i], image) if offered else ([(0, depth)], {0: image})
        tables = write_tables(directory, dmd, frames_i, given, store_words, prefix=f"board{i}_")
        plusargs += [f"+{names[table]}={path}" for table, path in tables.items()]
        trace_files.append(directory / f"board{i}_pins.txt")
        pulse_files.append(directory / f"board{i}_pulses.txt")
        plusargs += [f"+{names['pins']}={trace_files[-1] if traces else '-'}",
                     f"+{names['pulses']}={pulse_files[-1]}",
                     *oscillators[i].plusargs(names["clock"], BOARD_PERIOD_FS)]
    sync_file = directory / "master_pulses.txt"
    plusargs += [f"+{MASTER_PLUSARGS['pulses']}={sync_file}",
                 *master.plusargs(MASTER_PLUSARGS["clock"], MASTER_PERIOD_FS)]
    report = directory / "report.json"
    report.unlink(missing_ok=True)
    period_ps = master_period_cycles * MASTER_PERIOD_FS // 1000
    tb = {"regs": pack(Registers, p.registers(dmd)), "timing": responder_timing(model),
          "mode": TriggerMode.PERIODIC.value, "period": master_period_cycles, "min_period": master_period_cycles,
          "width": width, "frames": frames, "period_ps": period_ps, "boards": boards, "report": str(report),
          "max_ps": round((max_sim_s or (frames + 20) * period_ps * 2e-12) * 1e12),
          "status": [(n, f.offset, f.width) for n, f in data.Layout.cast(Status)],
          "loops": [(n, f.offset, f.width) for n, f in data.Layout.cast(LoopState)]}
    key = f"{slug(dmd.name)}-{boards}-{p.beats}-{store_words}"
    verilog = cocotb_run.converted(lambda: TiledRig(dmd, boards, beats=p.beats, store_words=store_words), TOPLEVEL,
                                   ["TiledRig", dmd, boards, p.beats, store_words])
    cocotb_run.run(verilog, toplevel=TOPLEVEL,
                   module="sim.tb.tiled_rig_tb", key=key, params=tb, extra_sources=SOURCES, plusargs=plusargs,
                   run_dir=directory / "run", build_args=VERILATOR_TIMING)
    result = json.loads(report.read_text())
    syncs = _read_times(sync_file)[0]
    return TiledRun(syncs=syncs, pulses=[_read_times(f) for f in pulse_files], status=result["status"],
                    loops=result["loops"],
                    counts=result["counts"], wall_s=result["wall_s"],
                    traces=trace_files if traces else [], models=[dlpc410_for(dmd, p) for _ in images])
