"""Pin traces of the fast system run, read back: the DLPC410 replay gives what stepping the model
every cycle gives, catches a responder that disagrees with the model, and keeps rule breaks;
GMII transmit traces give back their frames; a window of a trace becomes a VCD."""

import numpy as np
import pytest

from gateware.dlpc410.facts import TEST_DMD
from sim.fast_top import pin_layout
from sim.harness.layout import pack
from sim.models import gmii, trace
from sim.models.dlpc410 import RULES, Dlpc410, RuleBreak
from sim.models.dlpc410_replay import MODEL_PARAMS, sequences

LAYOUT = pin_layout(TEST_DMD.buses)
NAMES = [name for name, _ in LAYOUT]


def record(cycles, *, tamper_at=None):
    """What trace_recorder.v writes for ``cycles`` (per-cycle pin dicts), with the controller
    outputs a faithful responder drives (a reference model's), one of them flipped at
    ``tamper_at``."""
    reference = Dlpc410(TEST_DMD, **MODEL_PARAMS)
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


def test_gmii_frames_from_a_transmit_trace():
    frames = [bytes(range(60)), bytes(range(100, 180))]
    records, cycle = [(0, 0)], 3
    for dv, _er, byte in gmii.cycles(frames):
        records.append((cycle, byte | dv << 8))
        cycle += 1
    records.append((cycle, 0))
    assert trace.gmii_frames(records) == [gmii.wire_bytes(f) for f in frames]
