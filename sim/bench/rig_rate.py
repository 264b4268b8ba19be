"""A plan's 8-bit frame rate measured on the sequencer's generated Verilog
(:mod:`sim.rigs.seq_rig`): the ramp frame played back to back, the pins through the rule-checking
DLPC410 model, the commands the schedule model's cycle for cycle, every level of a frame between two
others exact. Used by the rate benchmarks (:mod:`sim.bench.rates_figures`,
:mod:`sim.bench.group_orders_figures`).
"""

import numpy as np

from gateware.dlpc410.trigger import PIN_TO_STROBE
from sim.rigs.seq_rig import run_rig
from sim.tb.plane_source import ramp_image
from sim.tb.seq_sim import frame_lights, period_light
from spec import schedule
from spec.facts import DMDS
from spec.registers import ResetMode

__all__ = ["FRAMES", "RIG_SOURCE", "measured_rate", "ready", "median_period", "same_as_model"]

#: Frames played back to back (the period is the median of the last ones).
FRAMES = 4
#: Where a rate measured by :func:`measured_rate` comes from (:mod:`flow.bench`), run ``name``.
RIG_SOURCE = ("gateware: sequencer Verilog (sim.rigs.seq_rig), rates rig: {what}, the ramp frame back to back, pins "
              "through the DLPC410 rule model, commands equal to the schedule model's, camera model on a frame "
              "between two others; run {name}")


def measured_rate(dmd_name, mode, strict, dclk, reading="ti", *, frames=FRAMES, name=None, plan=None):
    """Play ``frames`` frames back to back, the store stand-in feeding
    :func:`spec.schedule.row_rate_words` words a cycle; returns (measured period cycles, the
    plan, and the camera's largest grey error in LSB over the frame between two others, window
    holding it). ``plan``: play this one (early triggers held) rather than
    :func:`spec.schedule.plan`'s for ``mode`` under the settle ``reading`` (the rule model checks
    the reading the plan was made for: :func:`sim.tb.seq_sim.dlpc410_for`)."""
    dmd = DMDS[dmd_name]
    words = schedule.row_rate_words(dmd, dclk)
    plan = plan or schedule.plan(dmd, dclk, reset_mode=ResetMode[mode], strict_rst=strict, trigger_hold=True,
                                 words_per_cycle=words, reading=reading)
    p = plan.params
    first = ready(dmd, p, [schedule.Frame(0, 8)])
    # triggered: a trigger every half frame (held until every group is ready); chained: one
    pins = [first - PIN_TO_STROBE + k * plan.frame_cycles // 2 for k in range(1 if p.chain else 2 * frames - 1)]
    cycles = first + (frames + 1) * plan.frame_cycles
    run = run_rig(dmd, p, [(0, 8)], pins=pins, cycles=cycles, store_words=words,
                  name=name or f"rates_{dmd_name}_{mode.lower()}_{int(dclk / 1e6)}")
    # group 0's first pulse of each frame: the camera trigger rises ``camera_offset`` after its
    # command on the pins (sync out may stay high across back-to-back phased frames)
    frame_starts = [t - schedule.DECISION_TO_PINS - p.camera_offset for t, level in run.camera_out if level]
    assert len(frame_starts) >= frames, f"{len(frame_starts)} frames played"
    period = median_period(frame_starts)
    same_as_model(dmd, p, [schedule.Frame(0, 8)], pins, cycles, run, f"{dmd_name} {mode}")
    # and the frame between two others is exact in every level: the window holds it, from its
    # first pulse to its last group's final dark pulse (the next frame's trigger is obeyed only
    # after that pulse); chained, frames overlap (a group
    # starts the next while others end this one): the window is one period, from a frame's
    # first pulse to the next's (after the first frames, which start from the trigger), in
    # which every group shows the whole of its frame
    if p.chain:
        light = period_light(run.model, frame_starts[2], frame_starts[3])
    else:
        (light,) = frame_lights(run.model, run.frames()[1:2])
    error = float(np.abs(light / p.lsb - ramp_image(dmd, 0)).max())
    return period, plan, error


def ready(dmd, p, frames):
    """The cycle from which every group is loaded with the first of ``frames`` (schedule model)."""
    return max(g.loaded_at for g in schedule.simulate(dmd, p, frames).groups)


def median_period(starts):
    periods = [b - a for a, b in zip(starts, starts[1:], strict=False)]
    return sorted(periods)[len(periods) // 2]


def same_as_model(dmd, p, frames, pins, cycles, run, what):
    """The commands on the pins are the schedule model's for the same triggers, cycle for cycle."""
    model = schedule.simulate(dmd, p, frames, [t + PIN_TO_STROBE for t in pins], until=cycles)
    horizon = run.status["now"] - 2 * dmd.dclk_per_row
    assert [c for c in run.commands if c[0] < horizon] == [c for c in model.decoded() if c[0] < horizon], \
        f"{what}: commands differ from the schedule model's"
