"""Two DMDs in weighted light: 8, 12 and 16-bit frames back to back on two boards in lockstep.

Board A shows the high ``n - k`` bits of each pixel at full light, board B the low ``k`` bits
at ``2**-k`` of it (:mod:`host.weighted`, ``k = n // 2``); both play the same plan, a
``max(k, n - k)``-bit frame with the same least significant plane. Two boards of the tiled rig
(:mod:`sim.rigs.tiled_rig`: the sync master's and the boards' generated Verilog under Verilator,
each board on its own crystal, +-20 ppm, the clock loops off) on the full DLP7000 at DCLK 400 MHz
(two beats a cycle); the master in PERIODIC mode at the plan's frame period, the boards in SYNC.
Each board plays a stored sequence of two frames in turn (a ramp holding every n-bit level, and
a white flat field), a frame a sync pulse; every board's pins go through the rule-checking
DLPC410 model, and the light through the camera model on each board's mirrors, added at the two
weights (:mod:`sim.models.weighted_light_model`) over each span from one sync pulse to the next,
in real time (the boards' sync error as their pins show it), in units of board A's least
significant plane as its own clock times it.

The rows come from the store stand-in (:mod:`sim.tb.plane_source`), a transfer a cycle: at the
bus's pace, not the DDR2's. The rates are named ``_bus_pace``: the memory is not in the loop.

* the rate on the pins (board A's frame starts), the schedule model's beside it, and the
  published figures of 2024 (``spec.facts.ANCHORS``, as ``bounds.anchor_*``); the same again under the plan finder's
  fastest plan for the depth (``_best``: phased reset modes, other plane orders);
* the grey error of every level, the pulses late and the sync error (B's pulse less A's);
* the ratio error: board B's light 3 % off (``spec.facts.WEIGHTED["ratio_error"]``), untrimmed,
  and trimmed: the flat field read with one lamp at a time (the camera model as the sensor),
  ``host.weighted.measure`` and ``trim``, then a second run with the dim board's entries'
  ``lsb`` lengthened;
* the seed's camera experiment (:mod:`sim.bench.camera_figures`) for the 8-bit dual frame: a
  window of a frame period leading or lagging the ramp frame (black before and after) by 0-100 %:
  ``build/dual_misalignment.csv`` and ``.png``.

``python -m sim.bench.dual_figures`` prints them.
"""

import math

import numpy as np

from host import weighted
from sim.bench.camera_figures import SHIFTS_PCT, worst_by_shift, write_one_curve
from sim.models import weighted_light_model as light
from sim.rigs.tiled_rig import BOARD_PERIOD_FS, MASTER_PERIOD_FS, Oscillator, run_tiled
from spec.facts import DMDS, WEIGHTED

__all__ = ["run", "BITS", "OSCILLATORS", "dual_run", "misalignment"]

DMD = DMDS["dlp7000"]
DCLK_HZ = 400e6
BITS = (8, 12, 16)
#: Frames of each rate run (two stored frames in turn).
FRAMES = {8: 8, 12: 6, 16: 5}
OSCILLATORS = [Oscillator(20, jitter_ps=10, seed=1), Oscillator(-20, jitter_ps=10, seed=3)]
#: The crystals' error the master's period leaves room for, and the cycles for the boards'
#: sampling of the pulse (even cycles) and the synchroniser.
MARGIN_PPM = 50
MARGIN_CYCLES = 6
#: Board B's light off ``2**-k`` of A's before the trim: dim by the facts table's error.
ERROR = -WEIGHTED["ratio_error"].value
#: Shifts of the camera window the figures name.
SHOWN_PCT = (-10, -1, 1, 10)

SOURCE = ("gateware: tiled rig (sim.rigs.tiled_rig), two DLP7000 boards' and the sync master's Verilog under "
          "Verilator at DCLK 400 MHz, rows from the store stand-in at the bus's pace; every board's pins through "
          "the DLPC410 rule model, light through the camera model and sim.models.weighted_light_model; run {name}")
MODEL = "model: the schedule model's frame period (spec.schedule.plan at the dual depth, host.weighted)"


def _master_cycles(frame_cycles):
    """The master's period for frames of ``frame_cycles`` board cycles, with the margins."""
    return math.ceil((frame_cycles + MARGIN_CYCLES) * (1 + MARGIN_PPM * 1e-6) * BOARD_PERIOD_FS / MASTER_PERIOD_FS)


def scenes(bits):
    """The two stored frames: a ramp holding every n-bit level, and white."""
    ramp = (np.arange(DMD.rows * DMD.columns) % (1 << bits)).reshape(DMD.rows, DMD.columns).astype(np.uint16)
    return {0: ramp, 1: np.full_like(ramp, (1 << bits) - 1)}


def dual_run(bits, name, slots, stored, *, trimmed=None, best=False):
    """Both boards playing ``slots`` (a slot a frame) of ``stored`` (``{slot: n-bit image}``),
    with ``trimmed`` (a :class:`host.weighted.Trim`) the dim board's entries lengthened, under
    the plan finder's fastest plan with ``best`` (else global reset, MSB first):
    ``(dual plan, TiledRun, each board's rule-model run)``."""
    dual = weighted.plan(DMD, DCLK_HZ, bits, best=best)
    parts = {s: dual.images(image) for s, image in stored.items()}
    images, offered = [], []
    for board in ("a", "b"):
        images.append({s: parts[s][board] for s in stored})
        lsb = trimmed.entry_lsb(board, dual.lsb) if trimmed else 0
        offered.append([(s, dual.depth, 0, 1, {"lsb": lsb}) for s in slots])
    frame = weighted.trimmed_frame_cycles(dual, trimmed, DMD) if trimmed else dual.plan.frame_cycles
    run = run_tiled(DMD, dual.params(), images, oscillators=OSCILLATORS, frames=len(slots), depth=dual.depth,
                    master_period_cycles=_master_cycles(frame), name=name, offered=offered)
    assert run.counts["pulses"] >= len(slots) and not run.counts["not_ready"], run.counts
    boards = [run.board_run(i, DMD) for i in range(2)]
    return dual, run, boards


def _lights(run, boards, k, unit, span=None):
    """Each board's light over frame ``k``'s span (sync to sync, or ``span`` in ps), in units
    of ``unit`` cycles of board A's own clock: a camera calibrated on A's light, so that a clock
    error common to both boards scales the image as a gain would, and the boards' relative error
    stays in it (a 16-bit level is 15 ppm of full scale, less than the crystals' 20 ppm)."""
    t0, t1 = span or (run.syncs[k], run.syncs[k + 1])
    factor = 1000 * (t1 - t0) / (run.cycle_at(0, t1) - run.cycle_at(0, t0)) / BOARD_PERIOD_FS
    return [run.light(i, boards[i], t0, t1, unit) / factor for i in range(2)]


def _errors(dual, run, boards, slots, stored, ratio_error=0.0, *, only=None, unit=None):
    """The largest grey error (n-bit LSB) over the frames from the second to the one before the
    last (those ``only`` names, when given): light from one sync pulse to the next, the n-bit LSB
    ``unit`` cycles of A's light (default the plan's ``lsb``)."""
    worst = 0.0
    for k in range(1, len(slots) - 1):
        if only is not None and slots[k] != only:
            continue
        a, b = _lights(run, boards, k, unit or dual.lsb)
        seen = light.grey(a, b, dual.low_bits, ratio_error)
        worst = max(worst, float(np.abs(seen - stored[slots[k]]).max()))
    return worst


def _rate(bits, figures, *, best=False):
    """The rate run of ``bits``-bit frames (``best``: under the plan finder's plan, its figures
    named ``_best``); its figures into ``figures``."""
    name = f"dual_gray{bits}" + ("_best" if best else "")
    stored = scenes(bits)
    slots = [f % 2 for f in range(FRAMES[bits])]
    dual, run, boards = dual_run(bits, name, slots, stored, best=best)
    source = SOURCE.format(name=name)
    if best:
        source += f", the plan finder's plan ({dual.plan.params.reset_mode.name}, {dual.plan.binds})"
    starts = np.array([f[0] for f in run.frame_pulses()[0] if len(f)], dtype=np.float64)
    frame_ps = float(np.diff(starts).mean())
    shown = [[slot for _now, slot in board.releases][:len(slots) - 1] for board in boards]
    assert all(s == slots[:len(slots) - 1] for s in shown), shown
    prefix = f"dual.gray{bits}"
    at = "_dlp7000_best" if best else "_dlp7000"
    figures[f"{prefix}_rate_hz{at}_bus_pace"] = (1e12 / frame_ps, "Hz", source)
    figures[f"{prefix}_rate_hz{at}_model"] = (dual.rate_hz, "Hz", MODEL + (", the plan finder's" if best else ""))
    figures[f"{prefix}_gray_error_lsb_max{at}"] = (_errors(dual, run, boards, slots, stored), "LSB", source)
    figures[f"{prefix}_pulses_late{at}"] = (sum(s["late"] for s in run.status), "pulses", source)
    figures[f"{prefix}_sync_refused{at}"] = (run.counts["not_ready"], "pulses", source)
    errors = light.sync_errors_ns(run.pulses[0][0], run.pulses[1][0], run.syncs)
    figures[f"{prefix}_sync_error_ns_max{at}"] = (max(float(np.abs(e).max()) for e in errors), "ns", source)
    if best:
        return None
    figures[f"{prefix}_low_bits{at}"] = (dual.low_bits, "bits", source)
    untrimmed = _errors(dual, run, boards, slots, stored, ERROR, only=0)
    figures[f"dual.ratio_error_lsb_max_untrimmed_gray{bits}"] = (untrimmed, "LSB", source + f", B's light {ERROR:+.0%}")
    return dual, run, boards, slots


def _trimmed(bits, dual, run, boards, slots, figures):
    """The flat field read a lamp at a time, the trim, and a second run with it."""
    flat = next(k for k in range(1, len(slots) - 1) if slots[k] == 1)
    a, b = _lights(run, boards, flat, dual.lsb)
    reading_a, reading_b = light.flat_readings(a, b, dual.low_bits, ERROR)
    measured = weighted.measure(reading_a, reading_b, level_a=2 ** dual.high_bits - 1, level_b=2 ** dual.low_bits - 1,
                                low_bits=dual.low_bits, lsb_a=dual.lsb, lsb_b=dual.lsb)
    trim = weighted.trim(dual, measured, DMD)
    name = f"dual_gray{bits}_trimmed"
    stored = scenes(bits)
    slots = [0, 0, 0, 0]
    dual, run2, boards2 = dual_run(bits, name, slots, stored, trimmed=trim)
    source = SOURCE.format(name=name) + f", B's light {ERROR:+.0%}, trimmed from the flat field of run dual_gray{bits}"
    figures[f"dual.ratio_error_lsb_max_trimmed_gray{bits}"] = (
        _errors(dual, run2, boards2, slots, stored, ERROR, unit=trim.lsb_a), "LSB", source)
    figures[f"dual.ratio_error_measured_gray{bits}"] = (measured, "", source)
    figures[f"dual.trim_lsb_cycles_gray{bits}"] = (trim.lsb_b if trim.lsb_b != dual.lsb else trim.lsb_a, "cycle",
                                                    source)
    figures[f"dual.trim_pulses_late_gray{bits}"] = (sum(s["late"] for s in run2.status), "pulses", source)


def misalignment(bits=8, shifts=SHIFTS_PCT):
    """Per shift (% of a frame), the mean error (n-bit LSB) of each grey level: a window of one
    frame period from the ramp frame's first pulse on board A plus the shift, the ramp between
    black frames. ``{shift: array of 2**bits}``."""
    ramp = scenes(bits)[0]
    stored = {0: np.zeros_like(ramp), 1: ramp}
    slots = [0, 0, 1, 0, 0]
    dual, run, boards = dual_run(bits, f"dual_misalignment_gray{bits}", slots, stored)
    start = run.frame_pulses()[0][2][0]
    period = run.syncs[3] - run.syncs[2]
    levels = np.arange(1 << bits)
    order = np.argsort(ramp, axis=None, kind="stable")
    bounds = np.searchsorted(ramp.ravel()[order], levels)
    out = {}
    for pct in shifts:
        t0 = start + round(pct * period / 100)
        a, b = _lights(run, boards, None, dual.lsb, (t0, t0 + period))
        error = (light.grey(a, b, dual.low_bits) - ramp).ravel()[order]
        out[pct] = np.add.reduceat(error, bounds) / np.diff(np.append(bounds, error.size))
    return out


def run():
    figures = {}
    for bits in BITS:
        dual, run_, boards, slots = _rate(bits, figures)
        if bits in (8, 12):
            _trimmed(bits, dual, run_, boards, slots, figures)
        _rate(bits, figures, best=True)
    curves = misalignment(8)
    write_one_curve("dual_misalignment", curves, "8-bit dual frame")
    source = SOURCE.format(name="dual_misalignment_gray8") + ", the ramp between black frames, window of a frame period"
    for when, worst in worst_by_shift(curves, SHOWN_PCT).items():
        figures[f"dual.cam_{when}_error_lsb_max_gray8"] = (worst, "LSB", source)
    return figures


if __name__ == "__main__":
    for figure, (value, unit, *_source) in run().items():
        print(f"{figure:50s} {value:12.4f} {unit}")
