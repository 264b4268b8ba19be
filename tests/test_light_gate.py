"""Gated planes on the sequencer's generated Verilog (:mod:`sim.rigs.seq_rig`, the test DMD's
build the other rig tests use): a gated 8-bit ramp frame (:func:`spec.schedule.plan_gated`) plays
under the rule-checking DLPC410 model with no pulse late and the schedule model's commands; the
gate pin's edges are where the registers put them, the light is never on while mirrors move, and
the camera model (the mirrors' real delay and crossover, the light source's edges) sees every grey
level within half an LSB."""

import numpy as np
import pytest

from gateware.dlpc410.trigger import PIN_TO_STROBE
from sim.models.camera_model import Camera
from sim.rigs.seq_rig import run_rig
from sim.tb.plane_source import ramp_image
from spec import schedule
from spec.facts import TEST_DMD, TIMING

DMD = TEST_DMD
#: RST_ACTIVE and settle scaled down, as the other rig tests; the mirrors' timing is not.
FAST = {"t_rst_s": 20 / 200e6, "t_settle_s": 30 / 200e6}
#: The mirrors in the camera model: pulse to motion, and the crossover (the facts table's).
DELAY = round(TIMING["t_pulse_to_mirror"].value * schedule.FABRIC_HZ)
CROSSOVER = round(TIMING["t_crossover"].value * schedule.FABRIC_HZ)


def lit_intervals(edges):
    """``(on, off)`` of each high stretch of a pin's ``(cycle, level)`` changes."""
    rises = [t for t, level in edges if level]
    falls = [t for t, level in edges if not level]
    return list(zip(rises, falls, strict=True))


@pytest.fixture(scope="module")
def gated_run(tmp_path_factory):
    plan = schedule.plan_gated(DMD, 200e6, **FAST)
    p = plan.params
    frames = [schedule.Frame(0, 8)]
    pin = max(g.loaded_at for g in schedule.simulate(DMD, p, frames).groups) + 6
    model_run = schedule.simulate(DMD, p, frames, [pin + PIN_TO_STROBE])
    end = model_run.commands[-1][0] + 64
    run = run_rig(DMD, p, [(0, 8)], pins=[pin], cycles=end, name="gated_ramp_frame")
    return p, model_run, run, end


@pytest.mark.verilog
def test_gated_frame_plays_as_the_model(gated_run):
    p, model_run, run, end = gated_run
    assert p.gated_planes == 0xFF and p.gated_time >= p.light_lead + p.light_times[7] + schedule.LIGHT_FALL
    assert [c for c in run.commands if c[0] < end] == [c for c in model_run.decoded() if c[0] < end]
    assert run.status["late"] == 0 == model_run.late
    planes = [t for t, _, kind, _, _ in model_run.pulses if kind == "plane"]
    assert len(planes) == 8 and set(np.diff(planes)) == {p.gated_time}


@pytest.mark.verilog
def test_gate_edges_where_the_registers_say(gated_run):
    p, model_run, run, _ = gated_run
    want = []
    for t, _, kind, _, e in model_run.pulses:
        if kind == "plane":
            on = t + schedule.DECISION_TO_PINS + p.light_lead
            want += [(on, 1), (on + p.light_times[e], 0)]
    assert run.gate_out == want
    # the light (its fall included) off while any pulse's mirrors move, and before the next pulse
    pulses = [t + schedule.DECISION_TO_PINS for t, *_ in model_run.pulses]
    for on, off in lit_intervals(run.gate_out):
        dark_by = off + schedule.LIGHT_FALL
        assert all(dark_by <= t + DELAY or on >= t + schedule.MIRRORS_SETTLED for t in pulses), (on, off)
        assert dark_by <= min(t for t in pulses if t > on)


@pytest.mark.verilog
@pytest.mark.parametrize("edges", [0, 1])
def test_gated_grey_levels(gated_run, edges):
    p, _, run, _ = gated_run
    rise, fall = (schedule.LIGHT_RISE, schedule.LIGHT_FALL) if edges else (0, 0)
    gate = [(t - run.shift, level) for t, level in run.gate_out]
    camera = Camera(run.model, ramp_cycles=CROSSOVER, delay_cycles=DELAY, visible=False, gate=gate,
                    rise_cycles=rise, fall_cycles=fall)
    ((first, last),) = run.frames()
    grey = camera.image(first, last + DELAY + CROSSOVER) / p.light_times[0]
    want = ramp_image(DMD, 0).astype(np.float64)
    error = np.abs(grey - want).max()
    assert error <= (0.5 if edges else 1e-6), f"max error {error} LSB"
    # the same run with the light constant on sees the mirrors' whole frame instead
    constant = Camera(run.model, ramp_cycles=CROSSOVER, delay_cycles=DELAY, visible=False)
    assert np.abs(constant.image(first, last + DELAY + CROSSOVER) / p.light_times[0] - want).max() > 1
