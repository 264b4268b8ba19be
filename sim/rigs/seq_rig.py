"""The sequencer rig: the DLPC410 sequencer's generated Verilog, one Verilator build per DMD
geometry, every scenario given at run time.

:class:`SequencerRig` is :class:`sim.tb.plane_source.SourcedSequencer` (the sequencer and the
store stand-in) with, around it, only Verilog that runs without Python per cycle:

* the store stand-in's tables (planes, occupancy, frames offered) and the pin events (trigger,
  sync, soft trigger, early triggers) are ``file_memory.v`` memories loaded at start from files
  named by plusargs (:data:`PLUSARGS`); :class:`EventPlayer` plays the events;
* ``dlpc410_responder.v`` drives INIT_ACTIVE, RST_ACTIVE and ECP2_FINISHED, its cycle counts set
  at run time;
* ``trace_recorder.v`` writes the pins, sync and camera out, the time base's start and the
  slots released (:func:`rig_layout`) to a file (:func:`sim.rigs.fast_system_rig.dlpc410_side`).

The registers, the seed and the responder's timing are ports the testbench
(:mod:`sim.tb.seq_rig_tb`) sets once. :func:`run_rig` writes the files, runs the build for the
geometry and, after the run, replays the trace through the rule-checking DLPC410 model
(:func:`sim.models.trace.replay_dlpc410`, which also checks the responder against the model)
and returns what :func:`sim.tb.seq_sim.run_bench` returns for the same arguments.
"""

import functools
import json
from pathlib import Path

from amaranth import Instance, Module, Mux, Signal, Value
from amaranth.lib import data, wiring
from amaranth.lib.wiring import In, Out
from amaranth.utils import ceil_log2

from gateware.compose import members
from gateware.dlpc410.sequencer import Status
from gateware.registers import Registers
from gateware.store.layouts import SLOT_BITS
from sim.harness import cocotb_run
from sim.harness.layout import pack
from sim.harness.paths import ROOT, build_dir, slug
from sim.models import trace
from sim.rigs.fast_system_rig import PLUSARGS as FAST_PLUSARGS
from sim.rigs.fast_system_rig import dlpc410_side, pin_layout, power_on_reset
from sim.tb.plane_source import TABLES, OfferedFrame, SourcedSequencer, TableSignature, contents, table_depths
from sim.tb.seq_sim import Run, dlpc410_for
from spec.facts import DMDS
from spec.registers import TIME_BITS
from spec.schedule import DECISION_TO_PINS

__all__ = ["SequencerRig", "EventPlayer", "run_rig", "run_script", "rig_verilog", "analyse", "event_table",
           "rig_layout", "event_layout", "Timing", "file_table", "write_tables", "responder_timing", "SOURCES",
           "PLUSARGS", "INPUTS", "MAX_EVENTS", "TOPLEVEL"]

TOPLEVEL = "sequencer_rig"
#: The Verilog models the rig instantiates.
SOURCES = [ROOT / "sim" / "hdl" / name for name in ("file_memory.v", "dlpc410_responder.v", "trace_recorder.v")]
#: Plusargs naming the files: the tables and events in, the pin trace out.
PLUSARGS = {"planes": "SEQ_PLANES", "occupancy_map": "SEQ_OCCUPANCY", "offered": "SEQ_FRAMES",
            "events": "SEQ_EVENTS", "pins": FAST_PLUSARGS["pins"]}
#: The sequencer inputs the event player drives.
INPUTS = ("trigger_in", "sync_in", "soft_trigger")
#: Entries of the event table.
MAX_EVENTS = 64
#: Cycles an event holds its input high at most.
HOLD_BITS = 3


class Timing(data.Struct):
    """The responder's cycle counts (``dlpc410_responder.v``)."""
    rst_active_cycles: 32
    init_cycles: 32
    init_grace_cycles: 32
    ecp2_cycles: 32
    restart_at: 32
    restart_cycles: 32
    restart_ecp2_cycles: 32


def event_layout():
    """An entry of the event table: from ``at`` (the sequencer's time base ``now``, or with
    ``on_cycle`` the cycle count from the end of reset) each input of :data:`INPUTS` is high for
    its field's number of cycles (0: not touched)."""
    return data.StructLayout({"at": TIME_BITS, "on_cycle": 1, **{name: HOLD_BITS for name in INPUTS}})


def rig_layout(buses, beats=1):
    """The pin trace's record: :func:`sim.rigs.fast_system_rig.pin_layout`'s fields, ``running``
    (the time base counts: ``now`` is 1 on the first cycle it is high), the release stream (its
    ``ready`` is always high: each cycle with ``release_valid`` hands ``release_slot`` back), the
    sequencer's ``ready`` line (a trigger now would be obeyed at once) and its light gate."""
    return data.StructLayout({**{name: field.shape for name, field in pin_layout(buses, beats)},
                              "running": 1, "release_valid": 1, "release_slot": SLOT_BITS, "ready": 1,
                              "gate_out": 1})


class EventPlayer(wiring.Component):
    """Plays the event table on the sequencer's inputs.

    The entries are in order: those ``on_cycle`` first, by cycle, then the others by ``now``,
    one entry per instant (merged). An entry fires on its instant: ``on_cycle`` entries only
    while the time base has not started (``now`` at most 1), the others from ``now`` 2 on (what
    :func:`sim.tb.seq_sim.run_bench` does with its pin lists); an entry whose instant passed
    unfired is skipped. A fired input stays high for its hold; an entry for an input already
    high starts the hold again.

    Members
    -------
    table : Out(TableSignature)
        The event table (:func:`event_layout`), read asynchronously.
    now, cycle : In(TIME_BITS)
        The sequencer's time base, and cycles since the end of reset.
    trigger_in, sync_in, soft_trigger : Out(1)
    """

    def __init__(self, entries=MAX_EVENTS):
        self._entries = entries
        super().__init__({
            "table": Out(TableSignature(ceil_log2(entries + 1), event_layout())),
            "now": In(TIME_BITS),
            "cycle": In(TIME_BITS),
            **{name: Out(1) for name in INPUTS},
        })

    def elaborate(self, platform):
        m = Module()
        index = Signal(range(self._entries + 1))
        entry = self.table.data
        started = self.now >= 2
        due = Signal()
        fire = Signal()
        m.d.comb += [
            self.table.addr.eq(index),
            due.eq((index < self._entries)
                   & Mux(entry.on_cycle, (self.cycle >= entry.at) | started, started & (self.now >= entry.at))),
            fire.eq(due & Mux(entry.on_cycle, (self.cycle == entry.at) & ~started, self.now == entry.at)),
        ]
        with m.If(due):
            m.d.sync += index.eq(index + 1)
        for name in INPUTS:
            hold = entry[name]
            left = Signal(HOLD_BITS, name=f"{name}_left")
            start = fire & (hold != 0)
            m.d.comb += getattr(self, name).eq(start | (left != 0))
            with m.If(start):
                m.d.sync += left.eq(hold - 1)
            with m.Elif(left != 0):
                m.d.sync += left.eq(left - 1)
        return m


class SequencerRig(wiring.Component):
    """The sequencer, its store stand-in and its DLPC410 in Verilog, for one geometry.

    Parameters
    ----------
    dmd : DmdType
    beats, store_words : int
        As :class:`gateware.dlpc410.sequencer.Sequencer`'s.

    Members
    -------
    clk : In(1)
        The ``sync`` clock; the domain leaves reset ``RESET_CYCLES`` cycles after it starts
        (:func:`sim.rigs.fast_system_rig.power_on_reset`).
    regs, reload : In
        As the sequencer's.
    trigger_in : In(1)
        The trigger pin, with the event player's trigger.
    seed : In(64); reseed : In(1)
        The seed is loaded on the first cycle out of reset if ``reseed`` is high.
    timing : In(Timing)
        The responder's cycle counts; set before the clock starts.
    flush : In(1)
        Writes the trace recorder's buffered lines to its file.
    at_rest, sync_out, status : Out
        As the sequencer's.
    running : Out(1)
        The time base counts (``status.now`` is not 0).
    """

    def __init__(self, dmd, *, beats=1, store_words=1):
        self._dmd, self._beats, self._store_words = dmd, beats, store_words
        self._core = SourcedSequencer(dmd, beats=beats, store_words=store_words)
        super().__init__({
            "clk": In(1),
            **members(self._core, ("regs", "reload", "trigger_in", "seed", "reseed", "at_rest", "sync_out",
                                   "status")),
            "timing": In(Timing),
            "flush": In(1),
            "running": Out(1),
        })

    def elaborate(self, platform):
        m = Module()
        dmd = self._dmd
        power_on_reset(m, "sync", self.clk)
        m.submodules.core = core = self._core
        m.submodules.player = player = EventPlayer()
        cycle = Signal(TIME_BITS)
        m.d.sync += cycle.eq(cycle + 1)
        m.d.comb += [
            player.now.eq(core.status.now), player.cycle.eq(cycle),
            core.regs.eq(self.regs), core.reload.eq(self.reload), core.seed.eq(self.seed),
            core.reseed.eq(self.reseed & (cycle == 0)),
            core.trigger_in.eq(self.trigger_in | player.trigger_in),
            core.sync_in.eq(player.sync_in), core.soft_trigger.eq(player.soft_trigger),
            core.release.ready.eq(1),
            self.at_rest.eq(core.at_rest), self.sync_out.eq(core.sync_out), self.status.eq(core.status),
            self.running.eq(core.status.now != 0),
        ]
        depths = table_depths(dmd, self._store_words)
        for name in TABLES:
            file_table(m, name, getattr(core, name), depths[name])
        file_table(m, "events", player.table, MAX_EVENTS)
        dlpc410_side(m, dmd, core.pins, flush=self.flush, domain="sync", layout=rig_layout(dmd.buses, self._beats),
                     always=core.release.valid,
                     extra={"trigger_in": core.trigger_in, "sync_out": core.sync_out,
                            "camera_out": core.camera_out, "running": self.running,
                            "release_valid": core.release.valid, "release_slot": core.release.payload,
                            "ready": core.ready, "gate_out": core.gate_out},
                     **{name: getattr(self.timing, name) for name, _ in Timing.as_shape()})
        return m


def file_table(m, name, port, depth, plusarg=None):
    """A ``file_memory.v`` behind the read port ``port`` (a :class:`TableSignature` interface),
    loaded from the file of plusarg ``plusarg`` (default ``PLUSARGS[name]``)."""
    width = len(Value.cast(port.data))
    m.submodules[f"{name}_table"] = Instance(
        "file_memory", p_WIDTH=width, p_DEPTH=depth, p_ADDR_BITS=len(port.addr),
        p_PLUSARG=plusarg or PLUSARGS[name],
        i_addr=port.addr, o_data=port.data)


# --- running it ----------------------------------------------------------------------------------

def build_key(dmd, beats=1, store_words=1):
    """The build's key: ``dmd``'s name in the facts table, and the beats and store words a
    cycle when not 1."""
    name = next((key for key, known in DMDS.items() if known is dmd), slug(dmd.name))
    return name + (f"-{beats}beats" if beats != 1 else "") + (f"-{store_words}words" if store_words != 1 else "")


@functools.cache
def rig_verilog(dmd, beats=1, store_words=1):
    """The rig's Verilog, converted once per source tree (:func:`cocotb_run.converted`)."""
    return cocotb_run.converted(lambda: SequencerRig(dmd, beats=beats, store_words=store_words), TOPLEVEL,
                                ["SequencerRig", dmd, beats, store_words])


def write_hex(path, words, width):
    digits = (width + 3) // 4
    Path(path).write_text("".join(f"{int(w):0{digits}x}\n" for w in words))


def event_table(pins=(), sync_pins=(), soft=(), early_pins=()):
    """The event table (packed entries, merged per instant, in the player's order) of
    :func:`run_rig`'s pin arguments."""
    holds = {}
    for times, name, hold, on_cycle in ((pins, "trigger_in", 4, False), (sync_pins, "sync_in", 4, False),
                                        (soft, "soft_trigger", 1, False), (early_pins, "trigger_in", 1, True)):
        for at in times:
            assert at >= (1 if on_cycle else 2), f"{name} event at {at}: too early to be played"
            entry = holds.setdefault((not on_cycle, at), {})
            entry[name] = max(entry.get(name, 0), hold)
    assert len(holds) <= MAX_EVENTS, f"at most {MAX_EVENTS} event instants"
    layout = event_layout()
    return [pack(layout, {"at": at, "on_cycle": int(not by_now), **entry})
            for (by_now, at), entry in sorted(holds.items())]


def write_tables(directory, dmd, frames, images, store_words=1, prefix=""):
    """Write the store stand-in's tables (:func:`sim.tb.plane_source.contents`) to
    ``<directory>/<prefix><table>.hex``; returns ``{table: path}``."""
    c = contents(dmd, frames, images, store_words)
    files = {name: directory / f"{prefix}{name}.hex" for name in TABLES}
    for name, words, width in (("planes", c.planes, 64 * store_words), ("occupancy_map", c.occupancy, 8 * dmd.blocks),
                               ("offered", c.offered, OfferedFrame.as_shape().size)):
        write_hex(files[name], words, width)
    return files


def _stimulus(directory, dmd, frames, images, events, store_words=1):
    """Write the tables and the events; the plusargs naming them and the trace."""
    files = write_tables(directory, dmd, frames, images, store_words)
    files["events"] = directory / "events.hex"
    write_hex(files["events"], events, event_layout().size)
    files["pins"] = directory / "pins.txt"
    return files, [f"+{PLUSARGS[name]}={path}" for name, path in files.items()]


def responder_timing(model):
    """The responder's cycle counts (packed :class:`Timing`) of the controller ``model``."""
    return pack(Timing, {
        "rst_active_cycles": model.rst_active_cycles, "init_cycles": model.init_cycles,
        "init_grace_cycles": model.init_grace_cycles, "ecp2_cycles": model.ecp2_cycles,
        "restart_at": model.restart_at or 0, "restart_cycles": model.restart_cycles if model.restart_at else 0,
        "restart_ecp2_cycles": model.restart_ecp2_cycles})


def run_script(dmd, params, frames, images=None, *, script, name, model=None, seed=None, events=(),
               max_cycles, until_now=None, key=None, store_words=1):
    """Run the rig for ``dmd`` on a testbench ``script`` (:mod:`sim.tb.seq_rig_tb`); returns the
    :class:`Run` (:func:`analyse`, up to ``until_now``) with the testbench's report: its
    ``observed`` values, the clock ``cycles`` simulated and the simulation's ``wall_s``.
    ``model``: the controller (default :func:`sim.tb.seq_sim.dlpc410_for`), whose cycle counts
    the responder takes; ``events``: the event table (:func:`event_table`); ``max_cycles``: the
    script's time limit; ``key``: the build's (default: one per geometry, beats and store words:
    the sequencer is built for ``params.beats`` beats a cycle and ``store_words`` words a
    transfer from its store)."""
    model = dlpc410_for(dmd, params) if model is None else model
    directory = build_dir("seq_rig", slug(name))
    files, plusargs = _stimulus(directory, dmd, frames, images, list(events), store_words)
    report = directory / "report.json"
    report.unlink(missing_ok=True)
    p = {"regs": pack(Registers, params.registers(dmd)), "timing": responder_timing(model),
         "seed": seed, "script": script, "report": str(report), "max_cycles": max_cycles,
         "status": [(n, f.offset, f.width) for n, f in data.Layout.cast(Status)]}
    cocotb_run.run(rig_verilog(dmd, params.beats, store_words), toplevel=TOPLEVEL, module="sim.tb.seq_rig_tb",
                   key=key or build_key(dmd, params.beats, store_words),
                   params=p, extra_sources=SOURCES, plusargs=plusargs, run_dir=directory / "run")
    run = analyse(model, trace.read(files["pins"]), dmd, until_now=until_now)
    run.report = json.loads(report.read_text())
    return run


def run_rig(dmd, params, frames, images=None, *, pins=(), soft=(), cycles, name, early_pins=(), sync_pins=(),
            seed=None, model=None, key=None, store_words=1):
    """:func:`sim.tb.seq_sim.run_bench` on the rig: the same arguments, the same :class:`Run`.

    Runs until the sequencer's time base reaches ``cycles``. ``pins``: ``now`` values at which
    the trigger pin rises (high for 4 cycles), ``sync_pins`` the same for the sync pin,
    ``soft`` one-cycle software triggers; ``early_pins``: cycles (before initialisation ends)
    of one-cycle trigger pulses; ``seed``: loaded on the first cycle; ``key``: as
    :func:`run_script`'s. Raises the rule model's
    :class:`~sim.models.dlpc410_model.RuleBreak`, or :class:`~sim.models.trace.Mismatch` when the
    responder disagrees with the model."""
    script = [{"op": "until_now", "now": cycles}, {"op": "observe", "name": "end", "signals": ["status"]}]
    run = run_script(dmd, params, frames, images, script=script, name=name, model=model, seed=seed,
                     events=event_table(pins, sync_pins, soft, early_pins), max_cycles=cycles + 100_000,
                     until_now=cycles, key=key, store_words=store_words)
    run.status = run.report["observed"]["end"]["status"]
    return run


def analyse(model, pins, dmd, *, until_now=None):
    """Replay the trace ``pins`` through ``model`` (up to the cycle on which the time base was
    ``until_now``, default all of it) and gather the :class:`Run` (without status)."""
    layout = rig_layout(dmd.buses, model.beats)
    unpack = {name: (offset, mask) for name, offset, mask in trace.fields(layout)}

    def field(value, name):
        offset, mask = unpack[name]
        return value >> offset & mask

    start = next((c for c, v in pins if field(v, "running")), None)
    shift = 0 if start is None else 1 - start
    until = None if until_now is None else until_now - shift
    trace.replay_dlpc410(model, pins, layout, until=until)
    run = Run(model, shift=shift)
    last = {"sync_out": 0, "camera_out": 0, "ready": 0, "gate_out": 0}
    for cycle, value in pins:
        if until is not None and cycle > until:
            break
        now = cycle + shift
        if not field(value, "running"):
            continue
        if field(value, "release_valid"):
            run.releases.append((now, field(value, "release_slot")))
        for name, offset in (("sync_out", -1), ("camera_out", 0), ("ready", 0), ("gate_out", 0)):
            level = field(value, name)
            if level != last[name]:
                getattr(run, name).append((now + offset, level))
                last[name] = level
    run.commands = model.commands(shift - DECISION_TO_PINS)
    return run

