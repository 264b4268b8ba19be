"""``make sim``: the projector's core end to end on the default scene.

:func:`main` is the full-XGA run (:mod:`sim.rigs.xga_run`): the core's generated Verilog (MAC,
network stack, protocol, serialiser, store, sequencer) on the DLP7000 at TI timing under Verilator,
the frames played into GMII from a replay file, the Verilog MCB model on both memory ports, and the
DLPC410 pins recorded and checked after the run by the rule-checking DLPC410 model and the camera
model. Nothing in Python runs per cycle.

:func:`run` is the small-geometry run (128x96, RST_ACTIVE and settle scaled down) with every model
in Python per cycle and cocotbext-style GMII from Python: the end-to-end test of the suite.
"""

import json
import math
import time
from pathlib import Path

from vcd.gtkw import GTKWSave

from gateware.top.system import Projector
from sim.harness import cocotb_run
from sim.harness.paths import build_dir
from sim.harness.waves import declared
from sim.rigs import xga_run as xga
from spec import schedule
from spec.facts import DMDS
from spec.registers import PlaneOrder, ResetMode

__all__ = ["main", "run", "core", "core_verilog", "plan", "power_up_plan", "PARAMS", "XGA_FRAMES", "XGA_ENTRIES"]

MAC, IP, PORT = 0x02_00_00_00_00_01, 0x0A_00_00_02, 5000
DMD_NS = 5.0

#: Frames ``make sim`` stores, shows one by one, and then back to back.
XGA_FRAMES = 3
XGA_ONE_BY_ONE = 3
XGA_BACK_TO_BACK = 6
#: The entry table ``make sim`` plays its stored frames by (the slot of each entry, in a loop):
#: in order, the second twice (a frame shown again is not read from the network again).
XGA_ENTRIES = (0, 1, 1, 2)

#: The small-geometry system run's parameters (the testbench's ``params()``).
PARAMS = {"dmd": "test", "mac": "02:00:00:00:00:01", "ip": "10.0.0.2", "port": PORT,
          "memory_bytes": 4 * 2**20, "t_rst": 40, "t_settle": 60, "init_cycles": 200,
          "init_grace": 4, "mode": "GLOBAL", "order": "MSB_FIRST", "frames": 3, "seed": 1,
          "settle_after_send": 3000, "faults": True}


def plan(p, **changes):
    """The schedule a run configures through a sequencer record: ``p``'s DMD, scaled RST_ACTIVE
    and settle times, reset mode and plane order (``changes``: other :func:`schedule.plan`
    arguments)."""
    kwargs = dict(t_rst_s=p["t_rst"] * DMD_NS * 1e-9, t_settle_s=p["t_settle"] * DMD_NS * 1e-9, depth=8,
                  reset_mode=ResetMode[p["mode"]], order=PlaneOrder[p["order"]])
    return schedule.plan(DMDS[p["dmd"]], 1e9 / DMD_NS, **{**kwargs, **changes})


def power_up_plan(p):
    """The registers the core is built with: planes three times as long as the run's, so that a
    frame shown before the run's sequencer record is applied would not be the frame sent."""
    return plan(p, exposure_s=3 * plan(p).params.lsb * DMD_NS * 1e-9)


def core(p):
    """The small-geometry core, built as the platform is: disarmed, with power-up registers unlike
    any run's (the testbench configures and arms it through records)."""
    dmd = DMDS[p["dmd"]]
    return Projector(dmd, mac=MAC, ip=IP, port=PORT, regs=power_up_plan(p).params.registers(dmd),
                     armed=False, mdio_cycles=(40, 10))


def core_verilog(p):
    """:func:`core`'s Verilog, converted once while the sources stay the same: the system
    testbench's runs and the virtual projector share it."""
    dmd = DMDS[p["dmd"]]
    return cocotb_run.converted(lambda: core(p), "projector",
                                ["Projector", dmd, power_up_plan(p).params.registers(dmd)])


def run(key="test", testcase="frames_over_gmii_are_shown_exactly", **overrides):
    """Build and run one test of the system testbench (``testcase``); returns its report (dict)."""
    report = build_dir("system") / f"{key}-{testcase}.json"
    p = {**PARAMS, **overrides, "report": str(report)}
    build = cocotb_run.run(core_verilog(p), toplevel="projector", module="sim.tb.system_tb", key=key, params=p,
                           testcase=testcase)
    result = json.loads(report.read_text())
    result["build"] = str(build)
    return result


def latency(shown):
    """(typical, worst) trigger-to-first-pulse latency over the frames whose trigger found the
    sequencer ready (a held trigger waits for the frame before it by design)."""
    latencies = sorted(f["latency_cycles"] for f in shown if not f["held"])
    return latencies[len(latencies) // 2], latencies[-1]


def main(frames=None, dclk_hz=xga.DCLK_HZ, faults=None, window=False, dmd="dlp7000", group_orders=None):
    """``make sim``: the full-XGA run of :mod:`sim.rigs.xga_run` on the default scene; prints the
    figures. ``faults`` (``make sim FAULTS=stalls|rst|all``): the same run with the chips
    misbehaving (:data:`sim.rigs.xga_run.FAULTS`). ``window`` (``make sim WINDOW=1``): every signal
    of the core is dumped from the first frame's last datagram (every frame sent whole, that one
    held back) to just after its first clocking pulse, with a save file of its own. ``dmd`` (``make
    sim DMD=dlp9500``): the projector's core for another DMD (the DLP9500: four buses, 1920 of 2048
    columns seen). ``group_orders`` (``make sim GROUP_ORDERS=<seconds>``): the plan is the
    constraint solver's, dual reset's groups each in a plane order of its own
    (:mod:`spec.group_orders`), searched that long."""
    frames = frames or XGA_FRAMES
    name, dmd = dmd, DMDS[dmd]
    print(f"make sim: the projector's core (generated Verilog, Verilator) on the default scene, "
          f"{dmd.columns}x{dmd.rows} 8-bit ({dmd.name}) at DCLK {dclk_hz / 1e6:g} MHz, {frames} frames "
          f"sent over GMII from a replay file ("
          + ("every one whole, the first last, its last datagram held back for the wave window"
             if window else "the first whole, the others as deltas of it") + ") and stored as a "
          f"sequence played by an entry table (slots {list(XGA_ENTRIES)}, in a loop), {XGA_ONE_BY_ONE} "
          f"triggered one by one, then {XGA_BACK_TO_BACK} back to back; Verilog MCB model on both memory "
          f"ports; DLPC410 pins recorded and checked afterwards by the rule-checking DLPC410 model and the "
          f"camera model; TI timing (only INIT_ACTIVE shortened)")
    f = xga.FAULTS[faults] if faults else {}
    if "mcb_stall_permille" in f:
        print(f"faults: {f['mcb_stall_permille']} in 1000 memory commands stall up to {f['mcb_stall_max_ns']} ns "
              f"(seed {f['mcb_stall_seed']})")
    if "dlpc410_rst_extra" in f:
        print(f"faults: RST_ACTIVE held {f['dlpc410_rst_extra']} cycles longer than the facts table's time; "
              f"a first short run measures it (status rst_active_cycles_max) and the run is planned with it")
    t0 = time.monotonic()
    key = "-".join(["scene", *([name] if name != "dlp7000" else []), *([faults] if faults else []),
                    *(["window"] if window else []), *(["group-orders"] if group_orders else [])])
    r = xga.run(key, frames=frames, one_by_one=XGA_ONE_BY_ONE, back_to_back=XGA_BACK_TO_BACK, dclk_hz=dclk_hz,
                faults=faults, window=window, dmd=dmd, entries=XGA_ENTRIES, group_orders=group_orders)
    shown, status = r["frames"], r["status"]
    ns = 1e9 / xga.DMD_HZ
    typical, worst = latency(shown)
    optical = r["pulse_to_mirror_cycles"]
    periods = r["periods_measured"]
    measured = sorted(periods)[len(periods) // 2]
    print()
    print(f"DCLK: {r['dclk_hz'] / 1e6:g} MHz ({r['dclk_hz'] / xga.DMD_HZ:g} beats per {xga.DMD_HZ / 1e6:g} MHz cycle)")
    print(f"frames shown: {len(shown)} (slots {r['slots_played']}, each its entry's; entry records "
          f"{status['records_entry']}, entries skipped {status['sequence_entries_skipped']})")
    print(f"trigger pin to first clocking pulse: typical {typical} cycles ({typical * ns:.0f} ns), "
          f"worst {worst} cycles ({worst * ns:.0f} ns)")
    print(f"trigger pin to the optical change (+ {optical} cycles, pulse to mirror motion, facts "
          f"t_pulse_to_mirror): typical {typical + optical} cycles ({(typical + optical) * ns / 1e3:.2f} us), "
          f"worst {worst + optical} cycles ({(worst + optical) * ns / 1e3:.2f} us)")
    agree = ("frame starts equal the schedule model's" if r["compared_with_model"]
             else "the sequencer waits for late rows: not compared with the schedule model")
    order = "each group in its own order from its own offset" if r["order"] == "groups" else \
        f"{r['order']}, stagger {r['stagger_cycles']}"
    print(f"frame period back to back, measured on the pins: {measured} cycles = {xga.DMD_HZ / measured:.1f} Hz "
          f"({agree}; periods {periods}); schedule model (the plan finder's: {r['reset_mode']} reset, "
          f"{order}, LSB {r['lsb_cycles']} cycles, rows every {r['row_period']} cycles, t_rst {r['t_rst_cycles']} "
          f"cycles{' as measured' if r['t_rst_measured'] else ''}): {r['period_cycles']} "
          f"cycles = {r['rate_hz']:.1f} Hz")
    spans = sorted({f["span_cycles"] for f in shown})
    print(f"first to last pulse of each frame: {spans} cycles, model {r['model_span_cycles']}")
    drops = {k: v for k, v in status.items() if k.startswith("drop") and v}
    print(f"status reply: {status['frames']} Ethernet frames received, {status['accepted']} accepted, "
          f"drops {drops or 'none'} (one datagram per frame goes to another UDP port on purpose); "
          f"{status['records_image']} image records, {status['rows']} rows; "
          f"triggers {status['triggers']} (held {status['triggers_held']}), overruns {status['trigger_overruns']}, "
          f"frames shown {status['frames_shown']}, pulses late {status['pulses_late']}, row loads that waited "
          f"for the store {status['row_underruns']}, RST_ACTIVE late {status['rst_active_late']}, RST_ACTIVE "
          f"faults {status['rst_active_faults']}, longest RST_ACTIVE {status['rst_active_cycles_max']} cycles, "
          f"controller restarts {status['dlpc410_restarts']}")
    scene = r["scene"]
    if scene["deltas"]:
        print(f"scene over GigE, measured on the GMII pins at line rate (every frame complete in the store, none "
              f"dropped): the first frame whole, {scene['whole_frames_per_s']:.1f} frames/s; the next "
              f"{scene['deltas']} as deltas of it (rows carried {scene['delta_rows']} of {dmd.rows}), "
              f"{scene['delta_frames_per_s']:.0f} frames/s")
    if faults:
        print(f"memory commands stalled: {r['mcb_stalls']}")
    print(f"grey error of the reconstructed images: max {max(f['max_error_lsb'] for f in shown):g} LSB "
          f"({sum(f['wrong_pixels'] for f in shown)} pixels wrong)")
    print(f"simulation speed: {r['dmd_cycles'] / r['sim_wall_s']:.0f} dmd cycles per wall second "
          f"({r['dmd_cycles']:.0f} cycles = {r['dmd_cycles'] * ns / 1e6:.1f} ms in {r['sim_wall_s']:.0f} s)"
          + (f"; the first frame from its first packet to the last clocking pulse of the first frame shown: "
             f"{r['xga_frame_sim_wall_s']:.1f} s wall" if r["xga_frame_sim_wall_s"] is not None else ""))
    print(f"pin check and camera: {r['check_wall_s']:.0f} s over {r['trace_records']} trace records; "
          f"wall time {time.monotonic() - t0:.0f} s including the Verilator build")
    vcd = Path(r["waves"])
    save = write_save_file(vcd, PIN_GROUPS, "dlpc410", widths=r["waves_fields"], view=r["waves_view"],
                           markers=r["waves_markers"])
    print(f"waves: {vcd} (DLPC410 pins, trigger, sync and camera outputs of the first frame triggered, "
          f"written from the pin trace; the full design is not dumped at XGA)\n"
          f"  GTKWave save file: {save} (opens on the trigger and the first pulse, in a 1600x900 window; "
          f"markers A trigger, B first pulse, C last pulse)")
    if window:
        print_window(r["window"])
    exact = all(f["max_error_lsb"] == 0 for f in shown) and len(shown) == XGA_ONE_BY_ONE + XGA_BACK_TO_BACK
    return 0 if exact else 1


#: The core's ports by the block they belong to, for the GTKWave save file.
SAVE_GROUPS = {
    "clocks and resets": ["clk", "rst", "gmii_rx_clk", "gmii_tx_clk", "dmd_clk", "dmd_rst"],
    "MAC: GMII": ["gmii_rx[9:0]", "gmii_tx[9:0]"],
    "store: MCB port 0 (write, sync)": ["mcb_write__cmd_en", "mcb_write__cmd_instr[2:0]", "mcb_write__cmd_bl[5:0]",
                                        "mcb_write__cmd_byte_addr[29:0]", "mcb_write__wr_en",
                                        "mcb_write__wr_data[63:0]", "mcb_write__wr_count[6:0]"],
    "store: MCB port 1 (read, dmd)": ["mcb_read__cmd_en", "mcb_read__cmd_byte_addr[29:0]", "mcb_read__rd_en",
                                      "mcb_read__rd_data[127:0]", "mcb_read__rd_count[6:0]"],
    "sequencer: trigger and sync": ["trigger_in", "sync_out", "camera_out"],
    "sequencer: DLPC410 pins": ["dlpc__dvalid", "dlpc__rowmd[1:0]", "dlpc__rowad[10:0]", "dlpc__blkmd[1:0]",
                                "dlpc__blkad[3:0]", "dlpc__din_a[31:0]", "dlpc__din_b[31:0]",
                                "dlpc__rst_active", "dlpc__init_active", "dlpc__arstz"],
}


#: The core's blocks in the whole-core dump (``make sim WINDOW=1``): the scopes, under the core,
#: whose own signals each group of the save file shows.
WINDOW_GROUPS = {
    "MAC: GMII receive": ["ethernet.rx.mac"],
    "MAC: GMII transmit": ["ethernet.tx.mac"],
    "network stack": [f"ethernet.endpoint.stack{block}" for block in ("", ".eth", ".ipv4", ".udp", ".buffer")],
    "protocol: parser, rows, serialiser": ["ethernet.endpoint.parser", "ethernet.endpoint.rows", "serialiser"],
    "store: writer": ["store.writer", "store.writer.drain"],
    "store: slot table": ["store.slots.table"],
    "store: reader": ["store.reader", "store.reader.run_start"],
    "sequencer: control (broker, trigger, control)": ["broker", "sequencer.trigger", "sequencer.control"],
    "sequencer: planner": ["sequencer.planner"],
    "sequencer: bus": ["sequencer.bus", "sequencer.bus.cursor"],
}
#: The core's pins the last group shows: DLPC410, trigger, sync and camera.
WINDOW_PINS = [name.split("[")[0] for group in ("sequencer: trigger and sync", "sequencer: DLPC410 pins")
               for name in SAVE_GROUPS[group]]


def window_groups(vcd, core="fast_system.core"):
    """:data:`WINDOW_GROUPS` with the signals ``vcd`` declares (names under ``core``; Amaranth's
    anonymous ``$`` signals left out), then the core's DLPC410 pins; groups the dump lacks are
    left out."""
    scopes = declared(vcd)

    def own(scope):
        return [f"{scope}.{name}" if scope else name for name in scopes.get(".".join(filter(None, (core, scope))), [])
                if "$" not in name]
    groups = {group: [name for scope in where for name in own(scope)] for group, where in WINDOW_GROUPS.items()}
    groups["DLPC410 pins, trigger, sync and camera"] = [name for name in own("") if name.split("[")[0] in WINDOW_PINS]
    return {group: names for group, names in groups.items() if names}


def print_window(w):
    """Writes the whole-core dump's save file and says where both are."""
    vcd = Path(w["path"])
    start, end = w["span_ps"]
    markers = w["markers"]
    save = write_save_file(vcd, window_groups(vcd), "fast_system.core", view=(start, end), markers=markers)
    print(f"whole core dumped (every signal, VCD): {vcd}, {vcd.stat().st_size / 2**20:.0f} MiB, "
          f"{start / 1e6:.3f} to {end / 1e6:.3f} us ({(end - start) / 1e6:.1f} us of simulated time): the "
          f"first frame from the start of its last datagram (every frame sent whole, that one held back) "
          f"through the store to {xga.WINDOW_AFTER_US} us after its first clocking pulse\n"
          f"  GTKWave save file: {save} (grouped by block, buses in hex; opens on the window; markers "
          + ", ".join(f"{chr(ord('A') + i)} {name} {t / 1e6:.3f} us" for i, (name, t) in enumerate(markers.items()))
          + ")")


#: The pin trace's fields by what they are, for the XGA run's save file.
PIN_GROUPS = {
    "trigger, sync and camera": ["trigger_in", "sync_out", "camera_out"],
    "DLPC410 commands": ["dvalid", "rowmd", "rowad", "blkmd", "blkad", "rst2blkz"],
    "DLPC410 data": ["din_a", "din_b"],
    "DLPC410 state": ["arstz", "init_active", "rst_active", "ecp2_finished"],
}


#: The GTKWave window the save files ask for (``[size]``), the width of its signal name pane
#: (``[signals_width]``) and the width of the wave pane that leaves, less a margin, that the view
#: is fitted to: GTKWave 3.3 at 1600 pixels wide, its tree pane (SST) open, shows 1040 pixels of
#: waves beside a 260-pixel name pane (measured under Xvfb: 1600 less ~280 for the tree, 260 for
#: the names and ~20 for borders and the scroll bar). Without ``[size]`` GTKWave opens about
#: 1000 pixels wide whatever the screen, and the name pane is as wide as the longest name; with
#: ``[signals_width]`` it is at least that wide (values are cut to fit it, names never: a name of
#: more than ~30 characters widens it and the view ends that many pixels short of ``end``).
GTKWAVE_SIZE = (1600, 900)
GTKWAVE_SIGNALS_WIDTH = 260
GTKWAVE_WAVE_PIXELS = 1000
#: GTKWave's pixels per "frame" of its zoom: a zoom ``z`` puts ``2 ** -z`` time units in this
#: many pixels (GTKWave 3.3, zoom base 2; measured: zoom -15 shows 163.8 ps a pixel of a 1 ps
#: dump, -13.7 shows 66.5).
GTKWAVE_PIXELS_PER_FRAME = 200


def gtkwave_zoom(span, pixels=GTKWAVE_WAVE_PIXELS):
    """The GTKWave zoom that shows ``span`` time units of the dump in ``pixels`` of its wave
    pane. GTKWave's time unit is the dump's (ps for both of make sim's dumps, whose timescale is
    1 ps; a dump at 10 ps would count its times ten times over): a zoom ``z`` is ``2 ** -z`` units
    per :data:`GTKWAVE_PIXELS_PER_FRAME` pixels, so ``span / pixels`` units a pixel is
    ``z = -log2(span * 200 / pixels)``. (Without the 200 the view is 200 times too close: 81 ns
    of a 16.25 us view in 1200 pixels.)"""
    return -math.log2(max(1, span) * GTKWAVE_PIXELS_PER_FRAME / pixels)


def gtkwave_span(zoom, pixels=GTKWAVE_WAVE_PIXELS):
    """The time units ``pixels`` of GTKWave's wave pane show at ``zoom``: :func:`gtkwave_zoom`
    inverted."""
    return 2 ** -zoom * pixels / GTKWAVE_PIXELS_PER_FRAME


def write_save_file(vcd, groups=None, scope="projector", *, widths=None, view=None, markers=None):
    """A GTKWave save file beside ``vcd``: ``groups`` of signals (``widths``: ``{name: bits}``
    to name them as GTKWave does, ``name[n-1:0]``), buses in hex; ``view``: ``(start, end)`` the
    window it opens on, ``markers``: ``{name: time}`` named markers A, B, .. (VCD time units).
    GTKWave opens a :data:`GTKWAVE_SIZE` window with ``start`` at the left edge of the wave pane
    (``[timestart]``) and ``end`` :data:`GTKWAVE_WAVE_PIXELS` to the right of it, the rest of the
    pane past ``end``; a smaller window shows less past ``start``."""
    def label(name):
        bits = (widths or {}).get(name, 1)
        return f"{name}[{bits - 1}:0]" if bits > 1 else name
    path = vcd.with_suffix(".gtkw")
    named = list((markers or {}).items())
    with open(path, "w") as f:
        save = GTKWSave(f)
        save.dumpfile(str(vcd))
        save.savefile(str(path))
        save.size(*GTKWAVE_SIZE)
        save.pos(-1, -1)                            # where the window manager puts it
        save.signals_width(GTKWAVE_SIGNALS_WIDTH)   # the wave pane's width does not hang on names
        if view is not None:
            save.timestart(view[0])
        zoom = gtkwave_zoom(view[1] - view[0]) if view is not None else 0.0
        save.zoom_markers(zoom, named[0][1] if named else -1,
                          **{chr(ord("a") + k): t for k, (_name, t) in enumerate(named)})
        for k, (name, _t) in enumerate(named):
            f.write(f"[markername] {chr(ord('A') + k)}{name}\n")
        for group, signals in (groups or SAVE_GROUPS).items():
            with save.group(group):
                for name in signals:
                    save.trace(f"{scope}.{label(name)}" if widths else f"{scope}.{name}", datafmt="hex")
    return path
