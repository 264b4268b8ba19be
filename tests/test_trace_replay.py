"""Pin traces of the fast system run, read back: the DLPC410 replay gives what stepping the model
every cycle gives, catches a responder that disagrees with the model, and keeps rule breaks; GMII
transmit traces give back their frames; a window of a trace becomes a VCD. The Verilog responder and
recorder, on replayed sequences, agree with the model (:mod:`sim.tb.dlpc410_responder_tb`)."""

import os
import shutil
import subprocess

import numpy as np
import pytest

from sim.harness import cocotb_run
from sim.harness.layout import pack
from sim.harness.paths import build_dir
from sim.models import gmii_stim as gmii
from sim.models import trace
from sim.models.dlpc410_model import RULES, Dlpc410, RuleBreak
from sim.models.dlpc410_replay import MODEL_PARAMS, sequences
from sim.models.dlpc410_replay import NAMES as NAMES_OF_SEQUENCES
from sim.rigs.fast_system_rig import PLUSARGS, SOURCES, ResponderBench, pin_layout
from spec.facts import TEST_DMD

LAYOUT = pin_layout(TEST_DMD.buses)
NAMES = [name for name, _ in LAYOUT]
RESPONDER_TIMING = {"rst_active_cycles": MODEL_PARAMS["rst_active_cycles"], "init_cycles": MODEL_PARAMS["init_cycles"]}


def record(cycles, *, tamper_at=None, responder=None):
    """What trace_recorder.v writes for ``cycles`` (per-cycle pin dicts), with the controller
    outputs ``responder`` (default: a faithful one, the model's) drives, one of them flipped at
    ``tamper_at``."""
    reference = responder or Dlpc410(TEST_DMD, **MODEL_PARAMS)
    out, last = [], None
    for c, pins in enumerate(cycles):
        levels = reference.outputs()
        if c == tamper_at:
            levels = {**levels, "rst_active": 1 - levels["rst_active"]}
        value = pack(LAYOUT, {**{n: pins.get(n, 1 if n in ("rst2blkz", "wdt_enblz") else 0) for n in NAMES},
                              **{n: levels[n] for n in trace.COMPARED}})
        if c == 0 or value != last or pins.get("dvalid"):
            out.append((c, value))
        last = value
        reference.step(pins)
    return out


def test_replay_equals_stepping_every_cycle():
    cycles = sequences()["legal"]
    direct = Dlpc410(TEST_DMD, **MODEL_PARAMS)
    for pins in cycles:
        direct.step(pins)
    records = record(cycles)
    assert len(records) < len(cycles), "quiet cycles are not recorded"
    replayed = trace.replay_dlpc410(Dlpc410(TEST_DMD, **MODEL_PARAMS), records, LAYOUT)
    assert replayed.log == direct.log and replayed.log
    assert np.array_equal(replayed.mirrors, direct.mirrors)


def test_responder_disagreeing_with_the_model_is_caught():
    cycles = sequences()["legal"]
    records = record(cycles, tamper_at=len(cycles) - 3)
    with pytest.raises(trace.Mismatch, match="RST_ACTIVE"):
        trace.replay_dlpc410(Dlpc410(TEST_DMD, **MODEL_PARAMS), records, LAYOUT)


def test_responder_late_inside_an_unrecorded_gap_is_caught():
    late = Dlpc410(TEST_DMD, **{**MODEL_PARAMS, "rst_active_cycles": MODEL_PARAMS["rst_active_cycles"] + 1})
    with pytest.raises(trace.Mismatch, match="RST_ACTIVE=1"):
        trace.replay_dlpc410(Dlpc410(TEST_DMD, **MODEL_PARAMS), record(sequences()["legal"], responder=late), LAYOUT)


def test_rule_break_on_the_trace_is_raised():
    with pytest.raises(RuleBreak) as caught:
        trace.replay_dlpc410(Dlpc410(TEST_DMD, **MODEL_PARAMS), record(sequences()["illegal"]), LAYOUT)
    assert caught.value.rule is RULES["rst_active"]


def test_rising_edges_and_vcd(tmp_path):
    records = [(0, pack(LAYOUT, {"trigger_in": 0})), (5, pack(LAYOUT, {"trigger_in": 1})),
               (9, pack(LAYOUT, {"trigger_in": 0})), (20, pack(LAYOUT, {"trigger_in": 1}))]
    assert trace.rising_edges(records, LAYOUT, "trigger_in") == [5, 20]
    vcd = trace.write_vcd(tmp_path / "w.vcd", records, LAYOUT, start=4, end=21, ns_per_cycle=5).read_text()
    assert "$var wire 1" in vcd and "trigger_in" in vcd
    # changes at cycles 5, 9 and 20 relative to the window's start at 4
    assert [line for line in vcd.splitlines() if line.startswith("#")] == ["#0", "#5000", "#25000", "#80000"]


def _pins_vcd(tmp_path):
    records = [(0, pack(LAYOUT, {"trigger_in": 0})), (5, pack(LAYOUT, {"trigger_in": 1}))]
    return trace.write_vcd(tmp_path / "w.vcd", records, LAYOUT, start=0, end=10, ns_per_cycle=5)


def test_save_file_opens_on_the_markers(tmp_path):
    """The XGA run's GTKWave save file: it opens on the given window (zoomed to fit it), with
    named markers, buses named with their widths as GTKWave names them, in hex."""
    from sim.rigs.system_run import GTKWAVE_WAVE_PIXELS, write_save_file
    span = 5 * 2**12                                 # 1000 pixels of 20.48 units: zoom -12
    save = write_save_file(_pins_vcd(tmp_path), {"pins": ["trigger_in", "rowad"]}, "dlpc410",
                           widths={"trigger_in": 1, "rowad": 11}, view=(1000, 1000 + span),
                           markers={"trigger": 25000, "first pulse": 40000})
    text = save.read_text().splitlines()
    assert "[timestart] 1000" in text and "[size] 1600 900" in text and "[signals_width] 260" in text
    zoom, primary, *named = next(line for line in text if line.startswith("*"))[1:].split()
    assert float(zoom) == -12 and primary == "25000" and named[:3] == ["25000", "40000", "-1"] and len(named) == 26
    # GTKWave 3.3 shows 2**-zoom time units in 200 pixels: the wave pane's pixels show the view
    assert 2 ** -float(zoom) / 200 * GTKWAVE_WAVE_PIXELS == span
    assert "[markername] Atrigger" in text and "[markername] Bfirst pulse" in text
    assert "dlpc410.rowad[10:0]" in text and "dlpc410.trigger_in" in text
    assert "@22" in text[:text.index("dlpc410.trigger_in")]         # hex, right-justified, for both


@pytest.mark.parametrize("span", [1, 335_000, 16_250_000, 3_550_000_000])
def test_gtkwave_zoom_fits_the_span(span):
    from sim.rigs.system_run import gtkwave_span, gtkwave_zoom
    assert gtkwave_span(gtkwave_zoom(span)) == pytest.approx(span)
    assert gtkwave_span(gtkwave_zoom(span, 500), 500) == pytest.approx(span)


def test_pin_view_holds_the_trigger_and_the_first_pulse_apart():
    """The XGA run's view: the trigger and the first pulse with a margin each side, far enough
    apart in 1000 pixels to tell them apart, whether the pulse comes 7 or 5000 cycles after."""
    from sim.rigs.xga_run import WAVE_MARGIN, WAVE_WINDOW, _waves_view

    def ps(cycle):
        return cycle * 5000
    trigger = WAVE_WINDOW[0]
    for latency in (7, 5000):
        start, end = _waves_view(trigger, trigger + latency, ps)
        assert start == max(0, ps(trigger - max(latency, WAVE_MARGIN)))
        assert start < ps(trigger) < ps(trigger + latency) < end
        assert (ps(trigger) - start) / (end - start) * 1000 >= 50 or start == 0      # pixels of margin
        assert ps(latency) / (end - start) * 1000 >= 20                              # pixels apart


def test_gtkwave_opens_on_the_view(tmp_path):
    """GTKWave itself (under Xvfb, when both are installed) opens the save file with the view's
    start at the wave pane's left edge and its end inside the pane, at most a tenth more past it."""
    from sim.rigs.system_run import write_save_file
    if not (shutil.which("gtkwave") and shutil.which("Xvfb")):
        pytest.skip("gtkwave or Xvfb not installed")
    records = [(0, pack(LAYOUT, {"trigger_in": 0})), (1000, pack(LAYOUT, {"trigger_in": 1})),
               (1007, pack(LAYOUT, {"trigger_in": 0})), (4000, pack(LAYOUT, {"trigger_in": 1}))]
    vcd = trace.write_vcd(tmp_path / "w.vcd", records, LAYOUT, start=0, end=5000, ns_per_cycle=5)
    view = (4_900_000, 5_235_000)
    save = write_save_file(vcd, {"pins": ["trigger_in", "rowad"]}, "dlpc410", widths={"rowad": 11},
                           view=view, markers={"trigger": 5_000_000, "first pulse": 5_035_000})
    script = tmp_path / "view.tcl"
    script.write_text('puts "VIEW [gtkwave::getWindowStartTime] [gtkwave::getWindowEndTime]"\n'
                      "gtkwave::/File/Quit\n")
    read, write = os.pipe()                          # Xvfb writes the display number it took
    xvfb = subprocess.Popen(["Xvfb", "-displayfd", str(write), "-screen", "0", "1600x900x24"], pass_fds=[write],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        os.close(write)
        display = os.read(read, 16).decode().strip()
        out = subprocess.run(["gtkwave", "-S", str(script), str(save)], capture_output=True, text=True,
                             timeout=120, env={**os.environ, "DISPLAY": f":{display}"}).stdout
    finally:
        xvfb.terminate()
        xvfb.wait()
        os.close(read)
    start, end = (int(t) for t in next(line for line in out.splitlines() if line.startswith("VIEW")).split()[1:])
    assert start == view[0] and view[1] <= end <= view[1] + (view[1] - view[0]) // 10, (start, end)


def test_gmii_frames_from_a_transmit_trace():
    frames = [bytes(range(60)), bytes(range(100, 180))]
    records, cycle = [(0, 0)], 3
    for dv, _er, byte in gmii.cycles(frames):
        records.append((cycle, byte | dv << 8))
        cycle += 1
    records.append((cycle, 0))
    assert trace.gmii_frames(records) == [gmii.wire_bytes(f) for f in frames]


@pytest.mark.verilog
@pytest.mark.parametrize("name", NAMES_OF_SEQUENCES)
def test_responder_and_recorder_verilog(name):
    """The Verilog responder and recorder on the legal and the illegal sequence: the recorded
    trace, replayed, gives the command log of stepping the model every cycle (the responder's
    outputs equal to the model's on every recorded cycle), or the same rule break."""
    seqs = sequences()
    path = build_dir("cocotb", "responder_bench-test") / f"{name}.txt"
    path.unlink(missing_ok=True)
    bench = ResponderBench(TEST_DMD, [seqs[n] for n in NAMES_OF_SEQUENCES], **RESPONDER_TIMING)
    cocotb_run.run(bench, toplevel="responder_bench", module="sim.tb.dlpc410_responder_tb", key="test",
                   extra_sources=SOURCES, plusargs=[f"+{PLUSARGS['pins']}={path}"],
                   params={"select": NAMES_OF_SEQUENCES.index(name)}, top_signals_only=True)
    reference, replayed = Dlpc410(TEST_DMD, **MODEL_PARAMS), Dlpc410(TEST_DMD, **MODEL_PARAMS)
    try:
        reference.run(seqs[name])
    except RuleBreak as error:
        with pytest.raises(RuleBreak) as caught:
            trace.replay_dlpc410(replayed, trace.read(path), LAYOUT)
        assert (caught.value.rule, caught.value.cycle) == (error.rule, error.cycle)
        return
    trace.replay_dlpc410(replayed, trace.read(path), LAYOUT)
    assert replayed.log == reference.log and replayed.log
