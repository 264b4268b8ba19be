"""8-bit frame rates measured on the gateware, per reset mode and DCLK, at TI timing.

The sequencer's generated Verilog (:mod:`sim.seq_rig`: the store stand-in keeps up with any row
period, so these are the sequencer's and the DLPC410's rates, not the DDR2's) plays the ramp
frame of every grey level over and over, each trigger coming half a frame after the one before
and held until every group is ready (``trigger_hold``): the frames follow one another back to
back. RST_ACTIVE and settle are the facts table's (no scaling). The rule-checking DLPC410 model
checks every cycle of the pin trace, the commands must be the schedule model's cycle for cycle,
and, global, the camera model checks every level of a frame between two others; the period is
measured between the frames' first pulses on the pins. Beside each measured rate,
the schedule model's (``_model``). The DLP7000 in every reset mode at 200 and 400 MHz, and the
plan finder's choice (:mod:`spec.plan_search`) at each; the DLP9500 global at 400 MHz.
"""

import numpy as np

from gateware.dlpc410.trigger import PIN_TO_STROBE
from sim.seq_rig import run_rig
from sim.tb.plane_source import ramp_image
from sim.tb.seq_sim import frame_lights
from spec import plan_search, schedule
from spec.facts import DMDS
from spec.registers import ResetMode

__all__ = ["measured_rate", "run", "cases", "best", "CASES"]

#: (DMD, reset mode, strict RST_ACTIVE reading, DCLK): the plans measured.
CASES = [
    *[("dlp7000", mode, strict, dclk) for dclk in (200e6, 400e6)
      for mode, strict in (("GLOBAL", True), ("QUAD", True), ("DUAL", True), ("SINGLE", False))],
    ("dlp9500", "GLOBAL", True, 400e6),
]
#: Frames played back to back (the period is the median of the last ones).
FRAMES = 4


def measured_rate(dmd_name, mode, strict, dclk, *, frames=FRAMES, name=None, plan=None):
    """Play ``frames`` frames back to back; returns (measured period cycles, the plan). ``plan``:
    play this one (early triggers held) rather than :func:`spec.schedule.plan`'s for ``mode``."""
    dmd = DMDS[dmd_name]
    plan = plan or schedule.plan(dmd, dclk, reset_mode=ResetMode[mode], strict_rst=strict, trigger_hold=True)
    p = plan.params
    first = max(g.loaded_at for g in schedule.simulate(dmd, p, [schedule.Frame(0, 8)]).groups)
    pins = [first - PIN_TO_STROBE + k * plan.frame_cycles // 2 for k in range(2 * frames - 1)]
    cycles = first + (frames + 1) * plan.frame_cycles
    run = run_rig(dmd, p, [(0, 8)], pins=pins, cycles=cycles,
                  name=name or f"rates_{dmd_name}_{mode.lower()}_{int(dclk / 1e6)}")
    # group 0's first pulse of each frame: the camera trigger rises ``camera_offset + 1`` after
    # it (sync out may stay high across back-to-back phased frames)
    frame_starts = [t - 1 - p.camera_offset for t, level in run.camera_out if level]
    assert len(frame_starts) >= frames, f"{len(frame_starts)} frames played"
    periods = [b - a for a, b in zip(frame_starts, frame_starts[1:], strict=False)]
    period = sorted(periods)[len(periods) // 2]
    # the commands on the pins are the schedule model's, cycle for cycle
    model = schedule.simulate(dmd, p, [schedule.Frame(0, 8)], [t + PIN_TO_STROBE for t in pins], until=cycles)
    horizon = run.status["now"] - 2 * dmd.dclk_per_row
    assert [c for c in run.commands if c[0] < horizon] == [c for c in model.decoded() if c[0] < horizon], \
        f"{dmd_name} {mode}: commands differ from the schedule model's"
    # and, global, the frame between two others is exact in every level (phased groups overlap
    # the frames before and after: their levels are checked by the tests, triggered one by one)
    if mode == "GLOBAL":
        (light,) = frame_lights(run.model, run.frames()[1:2])
        expect = ramp_image(dmd, 0).astype(np.int64) * p.lsb
        assert np.array_equal(light, expect), f"{dmd_name} {mode}: a frame not exact"
    return period, plan


def run():
    measured = {}
    figures = cases(measured)
    figures.update(best(measured))
    return figures


def cases(measured):
    """The :data:`CASES`, each played on the gateware; ``measured`` gets each (period, plan)."""
    figures = {}
    for dmd_name, mode, strict, dclk in CASES:
        period, plan = measured_rate(dmd_name, mode, strict, dclk)
        measured[dmd_name, mode, strict, dclk] = period, plan
        key = f"{dmd_name}_{mode.lower()}_{int(dclk / 1e6)}mhz"
        figures[f"seq.gray8_rate_hz_{key}"] = (schedule.FABRIC_HZ / period, "Hz")
        figures[f"seq.gray8_rate_hz_{key}_model"] = (plan.rate_hz, "Hz")
    return figures


def best(measured=None):
    """The plan finder's choice for the DLP7000 under TI's rules (every reset mode, plane order,
    hide threshold) at each DCLK, played on the gateware (unless ``measured`` holds it already)."""
    figures, measured = {}, measured or {}
    for dclk in (200e6, 400e6):
        found = plan_search.find(DMDS["dlp7000"], dclk, trigger_hold=True)
        plan, mode = found.plan, found.best.reset_mode.name
        period, known = measured.get(("dlp7000", mode, True, dclk), (None, None))
        if known is None or known.params != plan.params:
            period, _ = measured_rate("dlp7000", mode, True, dclk, plan=plan,
                                      name=f"rates_dlp7000_best_{int(dclk / 1e6)}")
        print(f"plan finder, DLP7000 at {dclk / 1e6:g} MHz: {found.binds}\n{found.table()}")
        figures[f"seq.gray8_rate_hz_dlp7000_best_{int(dclk / 1e6)}mhz"] = (schedule.FABRIC_HZ / period, "Hz")
        figures[f"seq.gray8_rate_hz_dlp7000_best_{int(dclk / 1e6)}mhz_model"] = (plan.rate_hz, "Hz")
    return figures


if __name__ == "__main__":
    for figure, (value, unit) in run().items():
        print(f"{figure:50s} {value:10.1f} {unit}")
