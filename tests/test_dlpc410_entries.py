"""Frames shown as a sequence entry says (:class:`gateware.store.layouts.Showing`) on the
sequencer's generated Verilog (:mod:`sim.rigs.seq_rig`, testbench :mod:`sim.tb.seq_rig_tb`,
TEST_DMD): each frame's own least significant plane's time, frames that follow the one before with
no trigger after its dark time, a frame without a camera trigger, and the last frame of a sequence
played once, after which a trigger is ignored and counted; and entries that show some of their
frame's planes (``skip``). The command stream equals the schedule model's cycle for cycle (the model
takes the same settings, :class:`spec.schedule.Frame`), every DLPC410 rule holds, and the camera
sees each frame's every level at its own exposure."""

import numpy as np
import pytest

from gateware.dlpc410.trigger import PIN_TO_STROBE
from sim.models import bitplane_model as bitplane
from sim.rigs.seq_rig import run_rig
from sim.tb.plane_source import ramp_image
from sim.tb.seq_sim import frame_lights
from spec import schedule
from spec.facts import TEST_DMD
from spec.registers import ResetMode

DMD = TEST_DMD
FAST = {"t_rst_s": 20 / 200e6, "t_settle_s": 30 / 200e6}


def _frames(p):
    """(slot, depth, showing) of a sequence played once: a frame at the registers' settings that
    waits for its trigger, one of 6 bits at twice the exposure that follows it, one that follows
    with no camera trigger and wants a long dark time after it, and the last one."""
    return [
        (0, 8, {}),
        (1, 6, {"lsb": 2 * p.lsb, "follow": 1}),
        (0, 8, {"follow": 1, "camera_off": 1, "dark": 3 * p.dark_gap}),
        (1, 4, {"lsb": 4 * p.lsb, "follow": 1, "last": 1}),
    ]


@pytest.mark.verilog
@pytest.mark.parametrize("mode", [ResetMode.GLOBAL, ResetMode.DUAL])
def test_entries_show_each_frame_as_its_entry_says(mode, test_name):
    p = schedule.plan(DMD, 200e6, depth=8, reset_mode=mode, **FAST).params
    frames = _frames(p)
    model_frames = [schedule.Frame(slot, depth, sequence=True, **{k: v for k, v in showing.items()})
                    for slot, depth, showing in frames]
    first = max(g.loaded_at for g in schedule.simulate(DMD, p, model_frames[:1]).groups) + 10 - PIN_TO_STROBE
    probe = schedule.simulate(DMD, p, model_frames, [first + PIN_TO_STROBE])
    assert len(probe.frame_starts) == 4, "the frames after the first follow it with no trigger"
    # a second trigger once the last frame has played: ignored, counted
    late = probe.frame_starts[-1] + 2 * (probe.frame_starts[-1] - probe.frame_starts[-2])
    model = schedule.simulate(DMD, p, model_frames, [first + PIN_TO_STROBE, late + PIN_TO_STROBE])
    assert model.ended == 1 and len(model.accepted) == 1 and len(model.frame_starts) == 4
    end = late + 2000
    run = run_rig(DMD, p, [(slot, depth, 0, 1, showing) for slot, depth, showing in frames],
                  pins=[first, late], cycles=end, name=test_name)
    horizon = run.status["now"] - 2 * DMD.dclk_per_row
    assert [c for c in run.commands if c[0] < horizon] == [c for c in model.decoded() if c[0] < horizon]
    status = run.status
    assert (status["triggers"], status["after_end"], status["frames"], status["late"]) == (1, 1, 4, model.late)
    # (phased groups were staggered for the registers' exposure: another one may make pulses
    # late, as the model says; global ones never are)
    assert mode != ResetMode.GLOBAL or model.late == 0
    # the frame that follows waits the dark time after the one before's last pulse (group 0's)
    gap = model.frame_starts[3] - max(t for t, g, _kind, fi, _e in model.pulses if fi == 2 and g == 0)
    assert gap >= 3 * p.dark_gap
    # the camera pulses for every frame but the third
    rises = [t for t, level in run.camera_out if level]
    assert len(rises) == 3 and len(model.camera_starts) == 3
    assert [r - s for r, s in zip(rises, model.camera_starts, strict=True)] == [rises[0] - model.camera_starts[0]] * 3
    # every level of every frame at its own exposure (MSB first: a frame's top ``depth`` bits);
    # global, where a frame's pulses do not overlap the next frame's: the window from its first
    # pulse to its last (each of these frames ends dark), in the rule model's cycles
    if mode != ResetMode.GLOBAL:
        return
    for light, (slot, depth, showing) in zip(_lights(run, model, len(frames)), frames, strict=True):
        lsb = showing.get("lsb") or p.lsb
        expect = (ramp_image(DMD, slot).astype(np.int64) >> (8 - depth)) * lsb
        assert np.array_equal(light, expect), f"slot {slot}, {depth} bits"


def _lights(run, model, frames):
    """The camera's image of each of the first ``frames`` frames, global (a frame's pulses do not
    overlap the next frame's): the window from its first pulse to its last (each of these frames
    ends dark), in the rule model's cycles."""
    pins = schedule.DECISION_TO_PINS - run.shift       # a decision's cycle to its pins' in the rule model
    windows = [(min(t for t, _g, kind, fi, _e in model.pulses if fi == k and kind == "plane") + pins - 1,
                max(t for t, _g, _kind, fi, _e in model.pulses if fi == k) + pins) for k in range(frames)]
    return frame_lights(run.model, windows)


@pytest.mark.verilog
def test_entries_show_the_planes_they_pick(test_name):
    """Entries that leave out their frame's most significant planes (``skip``, the DLPC350's bit
    position), global, MSB first: an 8-bit frame, then following it with no trigger bits 3..4
    of the other frame (a 2-bit image), bit 0 of the first and bits 1..4 of the other. The store
    stand-in offers each with its lowest stored plane, as the store's answer gives it; the load
    jobs read the planes from there and look their blocks up in them (block 0 of the other frame
    has no bit 4 set: cleared, not loaded, for that plane), the commands equal the schedule
    model's, and every pixel's light in each frame is the image bits its entry names, each at
    its weight in the entry's depth (numpy, from the images)."""
    p = schedule.plan(DMD, 200e6, depth=8, **FAST).params
    images = {slot: ramp_image(DMD, slot) for slot in range(2)}
    images[1][:DMD.rows_per_block] &= 0x0F
    # (slot, depth, skip, showing)
    frames = [(0, 8, 0, {}), (1, 2, 3, {"follow": 1}), (0, 1, 7, {"follow": 1}),
              (1, 4, 3, {"follow": 1, "last": 1})]
    occupancy = {slot: tuple(int(x) for x in bitplane.occupancy(image, DMD.rows_per_block))
                 for slot, image in images.items()}
    model_frames = [schedule.Frame(slot, depth, occupancy[slot], sequence=True, skip=skip, **showing)
                    for slot, depth, skip, showing in frames]
    first = max(g.loaded_at for g in schedule.simulate(DMD, p, model_frames[:1]).groups) + 10 - PIN_TO_STROBE
    model = schedule.simulate(DMD, p, model_frames, [first + PIN_TO_STROBE])
    assert len(model.frame_starts) == 4 and model.late == 0
    end = model.pulses[-1][0] + 2000
    run = run_rig(DMD, p, [(slot, depth, 0, 1, showing, skip) for slot, depth, skip, showing in frames], images,
                  pins=[first], cycles=end, name=test_name)
    horizon = run.status["now"] - 2 * DMD.dclk_per_row
    assert [c for c in run.commands if c[0] < horizon] == [c for c in model.decoded() if c[0] < horizon]
    assert (run.status["frames"], run.status["late"]) == (4, 0)
    for light, (slot, depth, skip, _) in zip(_lights(run, model, len(frames)), frames, strict=True):
        bits = (images[slot].astype(np.int64) >> (8 - depth - skip)) & ((1 << depth) - 1)
        assert np.array_equal(light, bits * p.lsb), f"slot {slot}, {depth} bits below {skip}"
