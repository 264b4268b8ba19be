"""The full-XGA system run: the projector's core on the DLP7000 at TI timing, end to end.

:func:`run` encodes the default scene (1024x768, 8 bits) with the host encoder into scapy-built
datagrams, writes GMII replay files (a control record making the store keep the frames as a
sequence, then each frame), builds :class:`sim.rigs.fast_system_rig.FastSystem` with Verilator and
runs :mod:`sim.tb.fast_system_rig_tb` (no Python per cycle). The testbench first triggers a few
frames one by one, at different phases of the trigger against the clock (the latency), then triggers
faster than frames can be shown: each trigger is held until the sequencer is ready
(``trigger_hold``), so the stored frames play back to back at the rate the gateware reaches, and the
frame period is read from the pins. After the run it replays the DLPC410 pin trace through the
rule-checking model (every rule, and the Verilog responder's outputs against the model's),
reconstructs each frame with the camera model, checks the back-to-back frame starts against the
schedule model's, decodes the status reply from the transmit trace, and returns the figures.

With ``faults`` (a key of :data:`FAULTS`), the chips around the core misbehave: the memory
stalls commands at random (``stalls``), the controller holds RST_ACTIVE longer than the facts
table's time (``rst``), or both (``all``). Every rule must still be kept. A controller's
RST_ACTIVE is measured first, in a short run, and the run is planned with it (as a user plans
with ``rst_active_cycles_max``); memory stalls make the frame starts differ from the schedule
model's (the sequencer waits for late rows), so they are then reported, not compared.

With ``window``, every signal of the design is dumped for a bounded window that follows the
first frame shown from its last GMII byte to its first clocking pulse: every frame is sent whole,
the first one last, and its last datagram is held back until the one-by-one phase. The sequence
is complete, and the frame showable, only once that datagram is in; the window opens as it
starts, the first trigger comes right after its last byte (held until the frame is loaded) and
the window closes :data:`WINDOW_AFTER_US` after the frame's first clocking pulse
(:mod:`sim.tb.fast_system_rig_tb`), from a build with tracing of its own.

Timing: DCLK 400 MHz (two beats per 200 MHz ``dmd`` cycle) by default, or 200 MHz; RST_ACTIVE and
settle from the facts table (no scaling); only the DLPC410's initialisation (220 ms) is shortened,
to ``INIT_CYCLES``. The schedule is the plan finder's choice (:func:`spec.plan_search.find`) for
the read bandwidth the memory model gives the plane reader.
"""

import fcntl
import hashlib
import json
import math
import time
from pathlib import Path

import numpy as np
from scapy.layers.inet import IP, UDP
from scapy.layers.l2 import Ether
from scapy.packet import Raw

from host import codec
from sim.harness import cocotb_run
from sim.harness.paths import ROOT, build_dir
from sim.models import bitplane_model as bitplane
from sim.models import gmii_stim as gmii
from sim.models import trace
from sim.models.camera_model import Camera, to_lsb
from sim.models.dlpc410_model import Dlpc410
from sim.models.mcb_model import McbTiming
from sim.rigs.fast_system_rig import (
    INGEST_BYTES_PER_S,
    PLUSARGS,
    SOURCES,
    WINDOW_SOURCES,
    FastSystem,
    pin_layout,
    read_rate,
)
from sim.rigs.scene import default_scene
from spec import group_orders as spec_group_orders
from spec import plan_search, records, schedule
from spec.facts import DMDS, TIMING
from spec.registers import PlaneOrder, ResetMode

__all__ = ["run", "stream", "plan", "DMD", "DMD_HZ", "DCLK_HZ"]

DMD = DMDS["dlp7000"]
DMD_HZ, SYNC_HZ = schedule.FABRIC_HZ, 125e6
#: DCLK of the run unless told otherwise.
DCLK_HZ = 400e6
#: Triggers in the back-to-back phase come this much faster than the model's frame period.
FASTER = 0.95
MAC, IP_ADDR, PORT = 0x02_00_00_00_00_01, 0x0A_00_00_02, 5000
HOST_MAC, HOST_IP = "02:00:00:00:00:99", "10.0.0.1"
INIT_CYCLES, INIT_GRACE = 200, 4
TOPLEVEL = "fast_system"
#: The faulty runs (plusargs of the memory model and the responder): 1 command in 20 stalls up
#: to 2 us (a refresh is 160 ns, a bank conflict tens of ns); RST_ACTIVE is held 10 % (91
#: cycles) longer than the facts table's 4.54 us.
_STALLS = {"mcb_stall_permille": 50, "mcb_stall_max_ns": 2000, "mcb_stall_seed": 7}
_RST = {"dlpc410_rst_extra": 91}
FAULTS = {"stalls": _STALLS, "rst": _RST, "all": {**_STALLS, **_RST}}
#: Cycles more for every load of the solver's plans (``make sim GROUP_ORDERS``): before its pulse
#: and in the dark gap that covers a reload (:func:`spec.group_orders.sequencer_terms`).
GROUP_ORDERS_MARGIN = 300
#: The VCD of the pins covers the first triggered frame, from this many cycles before its trigger
#: to this many after its last pulse.
WAVE_WINDOW = (1000, 2000)
#: Its save file opens on the trigger and the frame's first clocking pulse: from a margin before
#: the trigger to two after the pulse (the pulse's command, RST_ACTIVE rising and sync and camera
#: out follow it), the margin the trigger-to-pulse latency but at least this many cycles, so that
#: the two edges (7 cycles apart at the default run) are tens of pixels apart, not one or two as
#: in a view of the whole RST_ACTIVE and the next load.
WAVE_MARGIN = 20
#: The plan finder's choices for the default runs, keyed as :func:`plan` keys them (copied from
#: ``build/plans`` after a run): a fresh clone plans without the search.
SHIPPED_PLANS = ROOT / "sim" / "plans"
#: The dump of every signal (``window``) closes this long after the frame's first clocking pulse:
#: the idle core dumps about 1.5 MB a microsecond (status counters of a thousand bits change
#: every cycle).
WINDOW_AFTER_US = 5


def plan(dclk_hz=DCLK_HZ, t_rst_cycles=None, dmd=DMD, group_orders=None):
    """The schedule for the run, as a user plans it (``python -m host configure --best``): the
    plan finder's fastest legal plan (every reset mode, plane order and hide threshold) for rows
    paced to the read bandwidth the memory leaves the plane reader, early triggers held;
    ``t_rst_cycles``: the controller's RST_ACTIVE as the projector measured it (default: the
    facts table's). ``group_orders``: seconds of the constraint solver's search for dual reset's
    groups each in a plane order of its own (``configure --group-orders``) instead. The finder's
    choice is kept in the build directory, keyed by the arguments and the planner's source, so
    that later runs plan only that one choice."""
    kwargs = {"words_per_cycle": read_rate(McbTiming(), DMD_HZ), "trigger_hold": True, "t_rst_cycles": t_rst_cycles,
              **({"margin": GROUP_ORDERS_MARGIN} if group_orders else {"depth": 8})}
    source = b"".join(path.read_bytes() for path in sorted((ROOT / "spec").rglob("*.py")))
    key = hashlib.sha256(json.dumps([dmd.name, dclk_hz, kwargs, group_orders]).encode() + source).hexdigest()[:16]
    path = build_dir("plans") / f"{key}.json"
    shipped = SHIPPED_PLANS / f"{key}.json"
    with open(path.with_suffix(".lock"), "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)          # (test workers that plan at once search once)
        found_before = path if path.exists() else shipped if shipped.exists() else None
        choice = json.loads(found_before.read_text()) if found_before else None
        if group_orders:
            if choice is None:
                found = spec_group_orders.find(dmd, dclk_hz, ResetMode.DUAL, seconds=group_orders, **kwargs)
                if found is None:
                    raise RuntimeError(f"the solver found no plan the sequencer plays on time in {group_orders:g} s")
                p = found[0].params
                choice = {"lsb": p.lsb, "orders": p.group_tables, "offsets": p.group_offsets}
                path.write_text(json.dumps(choice))
            _, base = spec_group_orders.sequencer_terms(dmd, dclk_hz, ResetMode.DUAL, **kwargs)
            return spec_group_orders.played(dmd, base, choice["lsb"], choice["orders"], choice["offsets"])
        if choice is not None:
            found = plan_search.candidate(dmd, dclk_hz, ResetMode[choice["reset_mode"]],
                                          PlaneOrder[choice["order"]], choice["hide"], **kwargs)
        else:
            found = plan_search.find(dmd, dclk_hz, **kwargs).best
            path.write_text(json.dumps({"reset_mode": found.reset_mode.name, "order": found.order.name,
                                        "hide": found.hide}))
    return found.plan


def calibrate(key, dclk_hz=DCLK_HZ, faults=None, log=print, dmd=DMD):
    """The controller's RST_ACTIVE as the projector measures it, as a user calibrates before a
    run (``python -m host configure --t-rst measured``): a short run on the facts table's plan
    (one frame, triggered twice), then the status reply's ``rst_active_cycles_max``. That run's
    images are not judged: its plan was not made for this controller."""
    r = run(f"{key}-calibrate", frames=1, one_by_one=1, back_to_back=1, dclk_hz=dclk_hz, faults=faults,
            log=log, calibrated=False, dmd=dmd)
    return r["status"]["rst_active_cycles_max"]


def top_verilog(the_plan, window=False, dmd=DMD):
    """The run's core as Verilog, converted once while the sources stay the same (``make sim``
    and the suite's run of the same plan share it)."""
    return cocotb_run.converted(lambda: top(the_plan, bool(window), dmd), TOPLEVEL,
                                ["FastSystem", dmd, the_plan.params, bool(window)])


def top(the_plan, window=False, dmd=DMD):
    return FastSystem(dmd, the_plan.params.registers(dmd), mac=MAC, ip=IP_ADDR, port=PORT,
                      clocks={"sync": SYNC_HZ, "dmd": DMD_HZ}, init_cycles=INIT_CYCLES,
                      init_grace_cycles=INIT_GRACE, beats=the_plan.params.beats, window=window)


def _datagrams(payloads, port=PORT):
    dst = ":".join(f"{MAC >> (8 * i) & 0xFF:02x}" for i in reversed(range(6)))
    ip = ".".join(str(IP_ADDR >> (8 * i) & 0xFF) for i in reversed(range(4)))
    return [bytes(Ether(src=HOST_MAC, dst=dst) / IP(src=HOST_IP, dst=ip) / UDP(sport=40000, dport=port)
                  / Raw(payload)) for payload in payloads]


def _replay_files(directory, images, hold_last=False, entries=None):
    """GMII replay files, as the sends the testbench makes in order (``path``, ``what``,
    ``kind``): a control record that makes the store keep the frames as a sequence (with
    ``entries``, a tuple of slots: then the entry table's records, and a control record that
    plays the sequence by them, in a loop), then one per
    frame (its image records, then the first record again addressed to another UDP port, which
    the stack must drop and count); and one with a status query. The first frame goes whole; each
    later one, as a user streams a moving target, goes as a delta of it: only the rows in which it
    differs from the first. ``hold_last`` (the wave window): every frame goes whole, the first one
    last, and its last datagram in a replay of its own (``held``, else None), sent later.
    Returns (sends, held, query, datagrams)."""
    sends, held, sequence = [], None, 0
    setup = directory / "sequence.bin"
    setup_records = [codec.control_record(sequence, sequence_length=len(images))]
    what = "sequence of stored frames (control record)"
    if entries:
        setup_records += [codec.entry_record(k, slot, 1 + k) for k, slot in enumerate(entries)]
        setup_records.append(codec.control_record(1 + len(entries), entries=len(entries), loop=1))
        what = f"sequence of stored frames played by {len(entries)} entries {list(entries)} (records)"
    gmii.replay_file(setup, _datagrams(setup_records))
    sequence, datagrams = len(setup_records), len(setup_records)
    sends.append({"path": str(setup), "what": what, "kind": "control"})
    order = list(range(len(images)))
    if hold_last:
        order = order[1:] + order[:1]
    for index in order:
        image, kind = images[index], "delta" if index and not hold_last else "whole"
        delta = {} if kind == "whole" else {"base": 0, "rows": codec.changed_rows(image, images[0]) if
                                            (image != images[0]).any() else [0]}
        payloads = codec.image_records(image, frame=index, sequence=sequence, **delta)
        sequence += len(payloads)
        stray = _datagrams(payloads[:1], port=PORT + 1)
        datagrams += len(payloads) + len(stray)
        what = f"frame {index + 1}/{len(images)}"
        if hold_last and index == 0:
            payloads, last = payloads[:-1], payloads[-1:]
            path = directory / "frame0_last.bin"
            gmii.replay_file(path, _datagrams(last))
            held = {"path": str(path), "what": f"{what}: its last datagram", "kind": "held"}
        path = directory / f"frame{index}.bin"
        gmii.replay_file(path, _datagrams(payloads) + stray)
        sends.append({"path": str(path), "what": what, "kind": kind})
    query = directory / "status_query.bin"
    gmii.replay_file(query, _datagrams([codec.status_query(sequence)]))
    return sends, held, str(query), datagrams + 1


def _status(tx_trace):
    """The status reply's fields, from the GMII transmit trace."""
    for frame in trace.gmii_frames(tx_trace):
        packet = Ether(frame[:-4])
        if UDP in packet and packet[UDP].sport == PORT:
            head, body, _ = codec.decode(bytes(packet[UDP].payload))
            if head["type"] == records.RecordType.STATUS_REPLY:
                return body
    raise AssertionError("no status reply on the transmit pins")


def run(key="xga", frames=3, *, one_by_one=2, back_to_back=6, dclk_hz=DCLK_HZ, faults=None, log=print,
        calibrated=True, window=False, dmd=DMD, entries=None, group_orders=None):
    """Build and run the XGA system simulation on ``frames`` frames of the default scene, stored
    as a sequence (played in slot order, or by ``entries``: the slot of each entry of its entry
    table, in a loop); ``one_by_one`` frames triggered each when the sequencer is ready, then
    ``back_to_back`` frames triggered faster than they can be shown. Returns the report (dict).
    Raises on a broken DLPC410 or memory rule, a responder mismatch, back-to-back frames that
    start other than the schedule model's (unless the memory stalls), or a missing status reply;
    the images' errors are in the report. ``faults``: a key of :data:`FAULTS`, the chips
    misbehave; when the controller's RST_ACTIVE is not the facts table's, the run is planned
    with the time the projector measured in a first short run (:func:`calibrate`), unless
    ``calibrated`` is false. ``window``: dumps every signal from the first frame's last GMII byte
    to its first clocking pulse (every frame sent whole; see the module's notes); the report's
    ``window`` says where, its span and its markers. ``dmd``:
    the DLP7000 (default) or another DMD of :data:`spec.facts.DMDS` (the DLP9500: four buses).
    ``group_orders``: the run plays the solver's plan of groups in orders of their own, searched
    this many seconds (:func:`plan`)."""
    t_rst_cycles = None
    if calibrated and "dlpc410_rst_extra" in FAULTS.get(faults, {}):
        t_rst_cycles = calibrate(key, dclk_hz, faults, log, dmd)
        log(f"RST_ACTIVE measured by the projector: {t_rst_cycles} cycles from the pulse; planned with it")
    the_plan = plan(dclk_hz, t_rst_cycles, dmd, group_orders)
    directory = build_dir("system", key)
    t0 = time.monotonic()
    images = default_scene(frames, dmd.rows, dmd.columns)
    sends, held, query, datagrams = _replay_files(directory, images, hold_last=window, entries=entries)
    log(f"scene encoded: {frames} frames, {datagrams} datagrams ({time.monotonic() - t0:.1f} s)")
    files = {name: directory / f"{name}.txt" for name in ("pins", "tx")}
    report_path = directory / "stimulus.json"
    p = {"frames": frames, "sends": sends, "held": held, "status_query": query, "replay": str(directory / "replay.bin"),
         "period_cycles": the_plan.frame_cycles, "one_by_one": one_by_one, "back_to_back": back_to_back,
         "fast_period_cycles": round(FASTER * the_plan.frame_cycles),
         # at or just after the first frame's last pulse: its first pulse comes within 8 cycles
         "last_pulse_cycles": _model_span(dmd, the_plan) + 8,
         # a frame's first plane is loaded about 155 us after its last byte (the stack forwards the
         # last datagram once its FCS is checked, then the plane is read from DDR2)
         "settle_us": 250,
         "margin_us": 20, "reply_us": 30, "progress_us": 2000, "report": str(report_path),
         "window": window and {"after_us": WINDOW_AFTER_US}}
    plusargs = _trace_plusargs(p["replay"], files)
    if faults:
        plusargs += [f"+{name}={value}" for name, value in FAULTS[faults].items()]
    if window:
        plusargs.append(f"+{PLUSARGS['window']}={directory / 'window.vcd'}")
    t_build = time.monotonic()
    # the window's build traces: a key of its own, so that the other runs stay untraced
    build = cocotb_run.run(top_verilog(the_plan, window, dmd), toplevel=TOPLEVEL, module="sim.tb.fast_system_rig_tb",
                           key=f"{_name(dmd)}-{the_plan.params.beats}beats" + ("-window" if window else ""),
                           params=p, extra_sources=SOURCES + (WINDOW_SOURCES if window else []), plusargs=plusargs,
                           waves=False, traced=bool(window), top_signals_only=True, testcase="stream_frames")
    stimulus = json.loads(report_path.read_text())
    sim_wall = stimulus["wall_s"]
    log(f"simulation done: build and run {time.monotonic() - t_build:.0f} s, of which the run {sim_wall:.0f} s; "
        f"checking the pins")
    report = analyse(the_plan, images, stimulus, files, one_by_one=one_by_one, back_to_back=back_to_back,
                     build=build, faults=faults, dmd=dmd, window=window, entries=entries)
    report["t_rst_cycles"], report["t_rst_measured"] = the_plan.params.t_rst, t_rst_cycles is not None
    if window:
        report["window"] = _window(directory / "window.vcd", stimulus, report)
    return report


def _window(path, stimulus, report):
    """The dump of every signal: its path, size, span and markers (ps of simulated time, as in
    the dump): the first frame's last GMII byte, the first trigger and the frame's first
    clocking pulse."""
    frame = report["frames"][0]
    # a pin trace cycle is the dmd edge that sampled the pins; the trigger's edge is known
    edge_ns = stimulus["trigger_edges_ns"][0]

    def ps(ns):
        return round(ns * 1e3)
    first_pulse_ns = edge_ns + (frame["start_cycle"] - frame["trigger_cycle"]) * 1e9 / DMD_HZ
    last_byte_ns = next(s["end_ns"] for s in stimulus["sends"] if s["kind"] == "held")
    w = stimulus["window"]
    return {"path": str(path), "bytes": path.stat().st_size, "span_ps": (ps(w["open_ns"]), ps(w["close_ns"])),
            "markers": {"last GMII byte": ps(last_byte_ns), "trigger": ps(stimulus["triggers_ns"][0]),
                        "first pulse": ps(first_pulse_ns)}}


def _frames_shown(pins, layout, pulses):
    """``(first pulse, last pulse)`` of every frame: sync out is high from a frame's first pulse
    to its last group's final dark pulse (it rises one cycle after the decision)."""
    rises = trace.rising_edges(pins, layout, "sync_out")
    frames = []
    for k, rise in enumerate(rises):
        end = rises[k + 1] if k + 1 < len(rises) else float("inf")
        mine = [c for c in pulses if rise - 1 <= c < end - 1]
        assert mine, f"frame {k}: sync out rose with no clocking pulse"
        frames.append((mine[0], mine[-1]))
    return frames


def _model_back_to_back(dmd, the_plan, images, slots, strobes):
    """The schedule model's frame starts for the stored frames of ``slots`` played in turn,
    triggered at ``strobes`` (relative cycles, the first when every group is ready)."""
    p = the_plan.params
    occupancy = [tuple(int(x) for x in bitplane.occupancy(image, dmd.rows_per_block)) for image in images]
    frames = [schedule.Frame(slot, 8, occupancy[slot], sequence=True) for slot in slots]
    ready = schedule.ready_cycle(dmd, p, frames[0])
    r = schedule.simulate(dmd, p, frames, [ready + s for s in strobes])
    assert r.late == 0 and r.overruns == 0, (r.late, r.overruns)
    return [t - r.frame_starts[0] for t in r.frame_starts]


def _trace_plusargs(replay, files):
    """The testbench's plusargs: the GMII replay file, and where the pin and transmit traces go."""
    return [f"+{PLUSARGS['replay']}={replay}", f"+{PLUSARGS['pins']}={files['pins']}",
            f"+{PLUSARGS['tx']}={files['tx']}"]


def _pins_checked(dmd, beats, path, rst_extra=0):
    """The pin trace at ``path`` replayed through the rule-checking DLPC410 model (its RST_ACTIVE
    ``rst_extra`` cycles longer than the facts table's): (layout, pins, model); raises on a
    broken rule."""
    layout = pin_layout(dmd.buses, beats)
    pins = trace.read(path)
    model = Dlpc410(dmd, beats=beats, clock_hz=DMD_HZ, init_cycles=INIT_CYCLES, init_grace_cycles=INIT_GRACE)
    model.rst_active_cycles += rst_extra
    trace.replay_dlpc410(model, pins, layout)
    return layout, pins, model


def analyse(the_plan, images, stimulus, files, *, one_by_one, back_to_back, build=None, faults=None, dmd=DMD,
            window=False, entries=None):
    t0 = time.monotonic()
    p = the_plan.params
    layout, pins, model = _pins_checked(dmd, p.beats, files["pins"],
                                        FAULTS[faults].get("dlpc410_rst_extra", 0) if faults else 0)
    triggers = trace.rising_edges(pins, layout, "trigger_in")
    pulses = [c.cycle for c in model.log if c.kind == "pulse"]
    period, lsb = the_plan.frame_cycles, p.lsb
    camera = Camera(model, ramp_cycles=0)
    frames = _frames_shown(pins, layout, pulses)
    assert len(frames) == len(triggers) == one_by_one + back_to_back, (len(frames), len(triggers))
    # the slot of each frame played: the entries' in turn, else the slots in order
    order = list(entries) if entries else list(range(len(images)))
    played = [order[k % len(order)] for k in range(len(frames))]
    shown = []
    for index, (first, last) in enumerate(frames):
        image = images[played[index]]
        light = to_lsb(camera.image(first, first + period), lsb)
        # (the camera sees the visible columns: the DLP9500's 1920 of the 2048 sent)
        error = np.abs(light - image[:, :light.shape[1]].astype(np.float64))
        trigger = triggers[index]
        shown.append({"trigger_cycle": trigger, "start_cycle": first, "latency_cycles": first - trigger,
                      # (with the window, the first trigger comes before its frame is loaded)
                      "held": index >= one_by_one + 1 or (window and index == 0), "span_cycles": last - first,
                      "max_error_lsb": float(error.max()), "wrong_pixels": int((error > 1e-9).sum())})
    # back to back: the frame starts the gateware made, against the schedule model's for the same
    # triggers (the first one found every group ready, the others were held)
    fast = shown[one_by_one:]
    starts = [f["start_cycle"] - fast[0]["start_cycle"] for f in fast]
    want = _model_back_to_back(dmd, the_plan, images, played[one_by_one:],
                               [f["trigger_cycle"] - fast[0]["trigger_cycle"] for f in fast])
    # memory stalls delay rows and pulses; a controller's own RST_ACTIVE time is in the plan
    compared = "mcb_stall_permille" not in FAULTS.get(faults, {})
    assert not compared or starts == want, f"back-to-back frame starts {starts}, the schedule model's {want}"
    periods = [b - a for a, b in zip(starts, starts[1:], strict=False)]
    status = _status(trace.read(files["tx"]))
    waves, start = None, triggers[0] - WAVE_WINDOW[0]

    def ps(cycle):
        return round((cycle - start) * 1e12 / DMD_HZ)
    if triggers:
        waves = trace.write_vcd(Path(files["pins"]).with_suffix(".vcd"), pins, layout,
                                start=start, end=frames[0][1] + WAVE_WINDOW[1], ns_per_cycle=1e9 / DMD_HZ)
    sends = stimulus["sends"]
    scene = _scene_rate(images, sends, status)
    return {
        "frames": shown,
        "slots_played": played,
        "dclk_hz": DMD_HZ * p.beats,
        "period_cycles": period,
        "periods_measured": periods,
        "rate_hz": the_plan.rate_hz,
        "model_span_cycles": _model_span(dmd, the_plan),
        "lsb_cycles": lsb,
        "row_period": the_plan.params.row_period,
        "reset_mode": p.reset_mode.name.lower(),
        "order": plan_search.order_name(p.order).lower().replace("_", " "),
        "stagger_cycles": p.stagger,
        "pulse_to_mirror_cycles": round(TIMING["t_pulse_to_mirror"].value * DMD_HZ),
        "back_to_back_model": want,
        "compared_with_model": compared,
        "faults": FAULTS[faults] if faults else None,
        "mcb_stalls": stimulus["mcb_stalls"],
        "status": status,
        "sends": sends,
        "scene": scene,
        "dmd_cycles": stimulus["sim_ns"] / (1e9 / DMD_HZ),
        "sim_wall_s": stimulus["wall_s"],
        # from the first frame's first packet to its last pulse (none marked with the window: its
        # trigger is held)
        "xga_frame_sim_wall_s": (stimulus["wall"]["first_frame_last_pulse"] - sends[1]["wall_start"]
                                 if "first_frame_last_pulse" in stimulus["wall"] else None),
        "trace_records": len(pins),
        "waves": str(waves),
        # the save file's view and named markers (ps in the VCD), the VCD's fields and widths
        "waves_view": _waves_view(triggers[0], frames[0][0], ps),
        "waves_markers": {"trigger": ps(triggers[0]), "first pulse": ps(frames[0][0]),
                          "last pulse": ps(frames[0][1])},
        "waves_fields": {name: mask.bit_length() for name, _, mask in trace.fields(layout)},
        "check_wall_s": time.monotonic() - t0,
        "build": str(build) if build else None,
    }


def _waves_view(trigger, first_pulse, ps):
    """The pin VCD's save file view, ``(start, end)`` in ps of the VCD (``ps`` of a cycle): see
    :data:`WAVE_MARGIN`."""
    margin = max(first_pulse - trigger, WAVE_MARGIN)
    return max(0, ps(trigger - margin)), ps(first_pulse + 2 * margin)


def _scene_rate(images, sends, status):
    """Frames a second over GigE, measured on the GMII pins: the whole first frame's records (and
    the stray datagram after them) from its first byte to its last, and the deltas' from the
    first delta's first byte to the last one's last byte, replayed at line rate; each counts only
    if the store completed every frame with nothing dropped (the status reply)."""
    dropped = {name: status[name] for name in ("drop_overflow", "mac_rx_dropped", "rows_incomplete",
                                              "store_rows_refused") if status[name]}
    assert not dropped and status["store_frames_complete"] == len(images), (dropped, status["store_frames_complete"])
    whole = next(s for s in sends if s["kind"] == "whole")
    whole_s = (whole["end_ns"] - whole["start_ns"]) * 1e-9
    deltas = [s for s in sends if s["kind"] == "delta"]
    delta_s = (deltas[-1]["end_ns"] - deltas[0]["start_ns"]) * 1e-9 if deltas else None
    return {"whole_frames_per_s": 1 / whole_s,
            "delta_frames_per_s": len(deltas) / delta_s if deltas else None,
            "deltas": len(deltas),
            "delta_rows": [int(len(codec.changed_rows(image, images[0]))) for image in images[1:]] if deltas else []}


def _name(dmd):
    """The key of ``dmd`` in :data:`spec.facts.DMDS`."""
    return next(name for name, known in DMDS.items() if known is dmd)


def _model_span(dmd, the_plan):
    """First to last clocking pulse of one frame in the schedule model."""
    p = the_plan.params
    fr = schedule.Frame(0, 8)
    r = schedule.simulate(dmd, p, [fr], [schedule.ready_cycle(dmd, p, fr)], max_frames=1)
    cycles = [c for c, *_ in r.pulses]
    return cycles[-1] - cycles[0]



def _stream_files(directory, images, whole):
    """GMII replay files for a stream: one per frame, the first whole (the key frame), each later
    one a delta of it (the rows in which the moving target differs from it: a delta's base must
    be a whole frame, which the store keeps while deltas use it), or whole too (``whole``).
    Returns (sends, query)."""
    sends, sequence = [], 0
    for index, image in enumerate(images):
        delta = {}
        if index and not whole:
            rows = codec.changed_rows(image, images[0])
            delta = {"base": 0, "rows": rows if len(rows) else [0]}
        payloads = codec.image_records(image, frame=index, sequence=sequence, **delta)
        sequence += len(payloads)
        path = directory / f"stream{index}.bin"
        gmii.replay_file(path, _datagrams(payloads))
        sends.append({"path": str(path), "what": f"frame {index + 1}/{len(images)}",
                      "kind": "delta" if delta else "whole", "wire_ns": path.stat().st_size // 2 * 8})
    query = directory / "status_query.bin"
    gmii.replay_file(query, _datagrams([codec.status_query(sequence)]))
    return sends, str(query)


def stream(key="stream", frames=6, *, whole=False, dclk_hz=DCLK_HZ, log=print, dmd=DMD):
    """A new frame at every trigger: ``frames`` frames of the default scene streamed over GMII
    (the store in its power-up streaming mode: each frame replaces the one before it), each sent
    while the one before it is shown, as a delta of the first (or whole: ``whole``); a trigger every
    frame period of the plan, or every frame's wire time when that is longer (whole frames).
    Returns the report: every frame on the pins with its error against the frame sent for that
    trigger, and the rate of new frames measured between the first and the last frame's first
    pulses. Raises when a frame is missing, repeated or wrong, or a counter says a record or a
    row was lost."""
    the_plan = plan(dclk_hz, None, dmd)
    directory = build_dir("system", key)
    images = default_scene(frames, dmd.rows, dmd.columns)
    sends, query = _stream_files(directory, images, whole)
    settle_us = 250
    # (the first frame goes before the first trigger, so its wire time does not set the pace)
    wire_cycles = max(s["wire_ns"] for s in sends[1:]) * DMD_HZ / 1e9 + settle_us * DMD_HZ / 1e6
    period = max(the_plan.frame_cycles, math.ceil(wire_cycles / 2) * 2)
    files = {name: directory / f"{name}.txt" for name in ("pins", "tx")}
    report_path = directory / "stimulus.json"
    p = {"sends": sends, "status_query": query, "replay": str(directory / "replay.bin"),
         "trigger_period_cycles": period, "settle_us": settle_us, "margin_us": 20, "reply_us": 30,
         "progress_us": 2000, "report": str(report_path)}
    plusargs = _trace_plusargs(p["replay"], files)
    start = time.monotonic()
    build = cocotb_run.run(top_verilog(the_plan, False, dmd), toplevel=TOPLEVEL, module="sim.tb.fast_system_rig_tb",
                           key=f"{_name(dmd)}-{the_plan.params.beats}beats", params=p, extra_sources=SOURCES,
                           plusargs=plusargs, waves=False, testcase="stream_new_frames", top_signals_only=True)
    stimulus = json.loads(report_path.read_text())
    log(f"simulation done: build and run {time.monotonic() - start:.0f} s; checking the pins")
    layout, pins, model = _pins_checked(dmd, the_plan.params.beats, files["pins"])
    triggers = trace.rising_edges(pins, layout, "trigger_in")
    shown = _frames_shown(pins, layout, [c.cycle for c in model.log if c.kind == "pulse"])
    assert len(shown) == len(triggers) == frames, f"{len(shown)} frames shown for {len(triggers)} triggers"
    camera, lsb = Camera(model, ramp_cycles=0), the_plan.params.lsb
    report = {"frames": [], "trigger_period_cycles": period, "period_cycles": the_plan.frame_cycles,
              "whole": whole, "sends": stimulus["sends"], "build": str(build)}
    for index, ((first, _last), trigger) in enumerate(zip(shown, triggers, strict=True)):
        light = to_lsb(camera.image(first, first + the_plan.frame_cycles), lsb)
        error = np.abs(light - images[index][:, :light.shape[1]].astype(np.float64))
        # a frame shown twice, or one left out, shows another frame's image: the scene moves
        others = [k for k, image in enumerate(images) if k != index
                  and np.array_equal(light, image[:, :light.shape[1]].astype(np.float64))]
        report["frames"].append({"trigger_cycle": trigger, "start_cycle": first, "latency_cycles": first - trigger,
                                 "max_error_lsb": float(error.max()), "wrong_pixels": int((error > 1e-9).sum()),
                                 "equals_frames": others})
    status = _status(trace.read(files["tx"]))
    counted = ("drop_overflow", "mac_rx_dropped", "rows_incomplete", "store_rows_refused", "store_rows_no_base",
               "store_frames_abandoned", "pulses_late")
    lost = {name: status[name] for name in counted if status[name]}
    assert not lost, lost
    assert status["store_frames_complete"] == frames and status["frames_shown"] == frames, status
    assert status["shown_frame"] == status["newest_frame"] == frames - 1, status
    starts = [f["start_cycle"] for f in report["frames"]]
    report["status"] = status
    report["new_frames_per_s"] = (frames - 1) * DMD_HZ / (starts[-1] - starts[0])
    report["wire_ms"] = [s["end_ns"] / 1e6 - s["start_ns"] / 1e6 for s in stimulus["sends"]]
    return report


#: Binary patterns from the store: frames sent (the first before the trigger, the others while
#: the patterns play) and the simulated time after the last one's last byte.
BINARY_FRAMES, BINARY_TAIL_US = 3, 600
#: The store's writes while 1-bit frames arrive at the GMII line rate: a bit per pixel byte.
BINARY_INGEST_BYTES_PER_S = INGEST_BYTES_PER_S / 8


def binary_plan(dclk_hz=DCLK_HZ, reset_mode=ResetMode.QUAD, dmd=DMD):
    """The plan of binary patterns from the store: 1-bit frames chained (each follows the one
    before with no trigger), rows paced to the read bandwidth the memory leaves the plane reader
    while GigE writes 1-bit frames at line rate (a pixel byte makes one bit of a plane), as
    :func:`plan` paces the 8-bit run's for 8-bit frames."""
    return schedule.plan(dmd, dclk_hz, depth=1, chain=True, reset_mode=reset_mode,
                         words_per_cycle=read_rate(McbTiming(), DMD_HZ, BINARY_INGEST_BYTES_PER_S))


def chain_files(directory, images, the_plan, dmd, *, bit_depth=1, name="binary"):
    """GMII replay files of a run of chained frames: the setup (a control record for a bit depth
    of ``bit_depth``, a sequencer record with the plan's registers, checked as the projector
    checks them), then each frame whole, in files named after ``name``. Returns (sends, query)."""
    p = the_plan.params
    setup = [codec.control_record(0, bit_depth=bit_depth),
             codec.sequencer_record(p.registers(dmd), 1, dmd=dmd, beats=p.beats)]
    path = directory / f"{name}_setup.bin"
    gmii.replay_file(path, _datagrams(setup))
    sends, sequence = [{"path": str(path), "what": f"bit depth {bit_depth} and the {name} plan's registers",
                        "kind": "control"}], len(setup)
    for index, image in enumerate(images):
        payloads = codec.image_records(image, frame=index, sequence=sequence)
        sequence += len(payloads)
        path = directory / f"{name}{index}.bin"
        gmii.replay_file(path, _datagrams(payloads))
        sends.append({"path": str(path), "what": f"frame {index + 1}/{len(images)}", "kind": "whole"})
    query = directory / "status_query.bin"
    gmii.replay_file(query, _datagrams([codec.status_query(sequence)]))
    return sends, str(query)


#: Counters of the status reply that say a chained run lost or delayed something.
CHAIN_LOSSES = ("drop_overflow", "mac_rx_dropped", "rows_incomplete", "store_rows_refused", "store_frames_abandoned",
                "pulses_late", "frames_bad_depth")


def run_chain(key, images, the_plan, dmd, *, tail_us, dclk_hz=DCLK_HZ, bit_depth=1, name="binary", log=print):
    """Play ``images`` chained from the store while GigE writes, on the core of ``make sim`` (the
    8-bit plan's build) under Verilator: the setup and the first frame, one trigger, then the other
    frames over GMII at line rate, ``tail_us`` more, the status query (:func:`chain_files`, the
    testbench's ``stream_chained_frames``). Returns (the testbench's report, the trace files, the build)."""
    build_plan = plan(dclk_hz, None, dmd)
    directory = build_dir("system", key)
    sends, query = chain_files(directory, images, the_plan, dmd, bit_depth=bit_depth, name=name)
    files = {kind: directory / f"{kind}.txt" for kind in ("pins", "tx")}
    report_path = directory / "stimulus.json"
    p = {"sends": sends, "status_query": query, "replay": str(directory / "replay.bin"), "settle_us": 250,
         "tail_us": tail_us, "margin_us": 20, "reply_us": 30, "progress_us": 2000, "report": str(report_path)}
    start = time.monotonic()
    build = cocotb_run.run(top_verilog(build_plan, False, dmd), toplevel=TOPLEVEL, module="sim.tb.fast_system_rig_tb",
                           key=f"{_name(dmd)}-{build_plan.params.beats}beats", params=p, extra_sources=SOURCES,
                           plusargs=_trace_plusargs(p["replay"], files), waves=False,
                           testcase="stream_chained_frames", top_signals_only=True)
    stimulus = json.loads(report_path.read_text())
    log(f"simulation done: build and run {time.monotonic() - start:.0f} s; checking the pins")
    return stimulus, files, build


def chain_status(files, frames):
    """The status reply of a chained run; raises when a counter says something was lost or late,
    or the store did not complete ``frames`` frames under one register set."""
    status = _status(trace.read(files["tx"]))
    lost = {name: status[name] for name in CHAIN_LOSSES if status.get(name)}
    assert not lost, lost
    assert status["store_frames_complete"] == frames and status["registers_applied"] == 1, status
    return status


def binary_stream(key="binary", frames=BINARY_FRAMES, *, reset_mode=ResetMode.QUAD, dclk_hz=DCLK_HZ, log=print,
                  dmd=DMD):
    """Binary patterns played from the store while GigE writes: the run's core (the 8-bit plan's
    build, as ``make sim``) is set over GMII to a bit depth of 1 and the binary plan's registers
    (:func:`binary_plan`); the first frame is stored and triggered once, and the chain of 1-bit
    patterns begins; the other frames follow over GMII at line rate, each written to the memory
    while the one before it repeats, and each taken at a pattern boundary once complete. The
    memory model serves both ports with its own timing (refresh, the ports sharing its
    bandwidth); nothing paces the rows but the plane reader and the sequencer.

    On the pins: every DLPC410 rule (the rule model); every pattern (block 0's clocking pulses)
    shows the most significant plane of one of the frames sent, exact in every pixel, the frames
    in the order sent, each at least once; the pattern periods. Returns the report; raises when a
    pattern shows anything else or a counter says something was lost."""
    the_plan = binary_plan(dclk_hz, reset_mode, dmd)
    images = default_scene(frames, dmd.rows, dmd.columns)
    planes = [(image >> 7).astype(bool) for image in images]
    assert all(not np.array_equal(a, b) for k, a in enumerate(planes) for b in planes[:k]), \
        "the frames' patterns must differ, or a repeat or a skip would not be seen"
    stimulus, files, build = run_chain(key, images, the_plan, dmd, tail_us=BINARY_TAIL_US, dclk_hz=dclk_hz, log=log)
    _layout, _pins, model = _pins_checked(dmd, the_plan.params.beats, files["pins"])
    starts = [c.cycle for c in model.log if c.kind == "pulse" and 0 in c.blocks]
    shown = []
    for k in range(len(starts) - 1):
        # each block's state latched by its pulse of pattern k (phased groups pulse a stagger
        # apart, all before the next pattern's first pulse)
        state = np.concatenate([next(s for c, s in reversed(history) if c < starts[k + 1])
                                for history in model.history])
        matches = [j for j, plane in enumerate(planes) if np.array_equal(state[:, :plane.shape[1]], plane)]
        if not matches:
            differs = [int((state[:, :plane.shape[1]] != plane).sum()) for plane in planes]
            raise AssertionError(f"pattern {k} at cycle {starts[k]} shows none of the frames sent "
                                 f"(pixels differing from each: {differs})")
        shown.append(matches[0])
    assert shown == sorted(shown) and sorted(set(shown)) == list(range(frames)), \
        f"frames shown in the patterns: {shown}"
    status = chain_status(files, frames)
    periods = [b - a for a, b in zip(starts, starts[1:], strict=False)]
    # the patterns played while GigE wrote: from the second frame's first byte to the last's last
    sent = stimulus["sends"]
    first_ns, last_ns = sent[2]["start_ns"], sent[-1]["end_ns"]
    ns = 1e9 / DMD_HZ
    during = [b - a for a, b in zip(starts, starts[1:], strict=False) if first_ns <= a * ns and b * ns <= last_ns]
    return {"plan": the_plan, "patterns": len(starts), "frames_shown": shown, "periods": periods,
            "periods_during_ingest": during, "period_cycles": the_plan.frame_cycles, "status": status,
            "ingest_ns": (first_ns, last_ns), "build": str(build),
            "sim_wall_s": stimulus["wall_s"]}


if __name__ == "__main__":
    print(json.dumps(run(frames=2, one_by_one=1, back_to_back=2), indent=1, default=str))
