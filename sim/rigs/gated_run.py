"""Gated 8-bit frames from the store while GigE writes: the light gate with the memory in the loop.

:func:`gated_stream` runs the projector's core of ``make sim`` (the 8-bit plan's build) on the
full DLP7000 at DCLK 400 MHz with the memory model behind its store. Over GMII it sets the
gated plan's registers (:func:`gated_plan`): every plane gated, each the shortest legal time,
frames chained one after the other with no trigger, the rows paced to what the memory leaves
the plane reader while GigE writes 8-bit frames at line rate. The first frame is stored and
triggered once; the others follow over GMII, each written to the memory while the one before it
repeats, each taken at a frame boundary once complete. Nothing paces the rows but the plane
reader and the sequencer.

On the pins: every DLPC410 rule (the rule model); the light of every frame between two others
through the camera model with the gate pin's waveform, the source's rise and fall and the
mirrors' delay (the facts table's): each one of the frames sent, the frames in the order sent;
the frame periods, the ones while GigE wrote apart.
"""

import json

import numpy as np

from sim.models import trace
from sim.models.camera_model import Camera, to_lsb
from sim.models.mcb_model import McbTiming
from sim.rigs import xga_run as xga
from sim.rigs.fast_system_rig import INGEST_BYTES_PER_S, read_rate
from sim.rigs.scene import default_scene
from spec import schedule
from spec.facts import TIMING

__all__ = ["gated_plan", "gated_stream", "FRAMES", "TAIL_US"]

#: Frames sent (the first before the trigger, the others while the frames play) and the
#: simulated time after the last one's last byte.
FRAMES, TAIL_US = 3, 2500
#: The mirrors in the camera model: pulse to motion, and the crossover (the facts table's).
DELAY = round(TIMING["t_pulse_to_mirror"].value * schedule.FABRIC_HZ)
CROSSOVER = round(TIMING["t_crossover"].value * schedule.FABRIC_HZ)


def gated_plan(dclk_hz=xga.DCLK_HZ, dmd=xga.DMD):
    """The gated plan (:func:`spec.schedule.plan_gated`) of chained 8-bit frames, rows paced to
    the read bandwidth the memory model leaves the plane reader while GigE writes 8-bit frames at
    line rate (as :func:`sim.rigs.xga_run.plan` paces the 8-bit run's)."""
    return schedule.plan_gated(dmd, dclk_hz, chain=True,
                               words_per_cycle=read_rate(McbTiming(), xga.DMD_HZ, INGEST_BYTES_PER_S))


def _frames(model, pins, layout, p):
    """``(first pulse, next frame's first pulse)`` of every frame on the pins: the camera pin
    rises ``camera_offset`` cycles after a frame's first pulse."""
    pulses = [c.cycle for c in model.log if c.kind == "pulse"]
    firsts = []
    for rise in trace.rising_edges(pins, layout, "camera_out"):
        first = max(c for c in pulses if c <= rise - p.camera_offset)
        assert rise - p.camera_offset - first <= 2, f"no pulse {p.camera_offset} cycles before the camera pin's rise"
        firsts.append(first)
    return list(zip(firsts, firsts[1:], strict=False))


def _shown(model, pins, layout, p, images, dmd):
    """For every frame between two others: (the image it matches, its largest error in LSB)."""
    camera = Camera(model, ramp_cycles=CROSSOVER, delay_cycles=DELAY, visible=False,
                    gate=trace.edges(pins, layout, "gate_out"),
                    rise_cycles=schedule.LIGHT_RISE, fall_cycles=schedule.LIGHT_FALL)
    columns = dmd.visible_columns
    out = []
    for first, end in _frames(model, pins, layout, p)[1:]:
        light = to_lsb(camera.image(first, end), p.light_times[0])[:, :columns]
        errors = [float(np.abs(light - image[:, :columns]).max()) for image in images]
        best = int(np.argmin(errors))
        out.append({"start_cycle": first, "period_cycles": end - first, "image": best, "error_lsb": errors[best]})
    return out


def gated_stream(key="gated", frames=FRAMES, *, tail_us=TAIL_US, dclk_hz=xga.DCLK_HZ, log=print, dmd=xga.DMD):
    """Run the gated frames from the store (see the module's notes). Returns the report; raises
    when a frame shows none of the frames sent (more than half an LSB off each), the frames are
    out of order, or a counter says something was lost or late."""
    the_plan = gated_plan(dclk_hz, dmd)
    images = default_scene(frames, dmd.rows, dmd.columns)
    stimulus, files, build = xga.run_chain(key, images, the_plan, dmd, tail_us=tail_us, dclk_hz=dclk_hz, bit_depth=8,
                                           name="gated", log=log)
    layout, pins, model = xga._pins_checked(dmd, the_plan.params.beats, files["pins"])
    shown = _shown(model, pins, layout, the_plan.params, images, dmd)
    order = [f["image"] for f in shown]
    worst = max(f["error_lsb"] for f in shown)
    assert worst <= 0.5, f"a frame shows none of the frames sent: {worst:.3f} LSB off the nearest"
    assert order == sorted(order) and order[-1] == frames - 1, f"frames shown: {order}"
    status = xga.chain_status(files, frames)
    sent = stimulus["sends"]
    first_ns, last_ns = sent[2]["start_ns"], sent[-1]["end_ns"]
    ns = 1e9 / xga.DMD_HZ
    during = [f["period_cycles"] for f in shown
              if first_ns <= f["start_cycle"] * ns and (f["start_cycle"] + f["period_cycles"]) * ns <= last_ns]
    return {"plan": the_plan, "frames": shown, "frames_shown": order, "error_lsb_max": worst,
            "periods": [f["period_cycles"] for f in shown], "periods_during_ingest": during,
            "period_cycles": the_plan.frame_cycles, "status": status, "ingest_ns": (first_ns, last_ns),
            "build": str(build), "sim_wall_s": stimulus["wall_s"]}


if __name__ == "__main__":
    report = gated_stream(frames=2, tail_us=1000)
    print(json.dumps({k: v for k, v in report.items() if k not in ("frames",)}, indent=1, default=str))
