"""Tiled display: the sync error between boards against run time, measured on the tiled rig.

A sync master and four boards, each on its own crystal, in one Verilator simulation of their
generated Verilog (:mod:`sim.rigs.tiled_rig`). The crystals are off by up to 100 ppm either way, one
drifts (a temperature change, sped up so that a short run sees it: 1,000 ppm/s), two jitter.
Each board starts its frame on the master's pulse, so its error does not build up from one
frame to the next. Within a frame it is the board's sampling of the pulse plus its clock's
error times the time since the pulse; each board's clock loop
(:class:`gateware.sync.clock_trim.ClockTrim`, pulling the board's VCXO) removes both once
locked: the boards keep the master's rate and take each pulse on the same edge.

* The long run, loops on: 10,000 frames of 4 planes on the test DMD (1,458 cycles a frame;
  8-plane frames would take 40 minutes to simulate). The spread of the boards' clocking pulses
  at every pulse of every frame, in ns, per 500 frames against the run time, with each board's
  rate measured from its pulses' times: ``build/sync_spread.csv`` and ``.png``.
* The same clocks with the loops off, 2,000 frames: the sampling (the bus decides on even
  cycles: up to two cycles apart) and the drift.
* 8-plane frames, loops on (their pins through the rule-checking DLPC410 model, and one camera
  over the whole scene from one pulse to the next, in real time: the error either side of each
  seam) and off (the check of the extrapolation: the spread predicted from the 4-plane run's
  figures against the one measured).
* The anchor register compared (:func:`anchors`): where in the plane order the frame starts on
  the pulse, loops off, under three camera windows.
* Extrapolated to the DLP7000's 8-bit frame (the schedule model's period) and to hours: a frame
  restarts on each pulse, so the spread depends on the clocks' difference at that moment, not on
  the run time: without the loops the crystals' tolerance (+-100 ppm at any temperature) bounds
  it, with them the loop's remaining error at that period (its model, :func:`sim.models
  .clock_trim.lock`, checked against the gateware at the small DMD's periods).
"""

from dataclasses import replace

import numpy as np

from sim.bench.tables import label, pyplot, save_figure, write_table
from sim.models import clock_trim_model as clock_trim
from sim.rigs.tiled_rig import BOARD_PERIOD_FS, Oscillator, master_period, run_tiled, tiles
from sim.tb.seq_sim import CAMERA_DELAY, CAMERA_RAMP
from spec import schedule
from spec.facts import DMDS, TEST_DMD
from spec.registers import PlaneOrder

__all__ = ["run", "anchors", "OSCILLATORS", "MASTER", "FRAMES", "CHUNK", "ANCHORS"]

OSCILLATORS = [Oscillator(100, jitter_ps=10, seed=1), Oscillator(-100, jitter_ps=30, seed=3),
               Oscillator(37, seed=5), Oscillator(-61, ramp_ppm_per_s=1000, jitter_ps=20, seed=7)]
MASTER = Oscillator(-20, seed=11)
#: Frames of the long run, and how many make a row of the table.
FRAMES = 10_000
CHUNK = 500
#: Frames of the run with the loops off.
UNTRIMMED_FRAMES = 2_000
#: Frames of the 8-plane run (its pins recorded and checked by the rule model, and the camera).
EIGHT_FRAMES = 250
#: The crystals' tolerance the extrapolation takes (any temperature).
PPM_TOLERANCE = 100
#: Where a figure of the tiled rig's run ``name`` comes from (:mod:`flow.bench`).
TILED_SOURCE = ("gateware: tiled rig (sim.rigs.tiled_rig), the sync master's and the boards' Verilog under Verilator, "
                "each on its own crystal model; run {name}")
#: ... and its light: every board's pins through the DLPC410 rule model, one camera over the tiles.
CAMERA_SOURCE = TILED_SOURCE + ", pins through the DLPC410 rule model, light through the camera model"


def _plan(depth, **kw):
    return schedule.plan(TEST_DMD, 200e6, depth=depth, t_rst_s=20 / 200e6, t_settle_s=30 / 200e6, **kw)


def _tiles():
    return tiles(TEST_DMD, len(OSCILLATORS), row_step=37)


def _run(depth, frames, name, *, trim, traces=False, **plan_kw):
    plan = _plan(depth, **plan_kw)
    return run_tiled(TEST_DMD, plan.params, _tiles(), oscillators=OSCILLATORS, master=MASTER, frames=frames,
                     master_period_cycles=master_period(plan.frame_cycles), name=name, traces=traces, depth=depth,
                     trim=trim)


def _boards(run):
    """Every board's pins through the rule-checking DLPC410 model (once: the models keep their
    state)."""
    return [run.board_run(i, TEST_DMD) for i in range(len(OSCILLATORS))]


def _seam_errors(run, boards, lsb, first, span=None):
    """Per frame from ``first`` to the one before the last, a camera over the whole scene from one sync
    pulse to the next, in real time (or over ``span``, ``(t0, t1)`` in ps after the pulse): the
    largest error (LSB) on the columns either side of a seam, and anywhere; and the pixels whose
    light, rounded to a level, is not their image's. ``boards``: :func:`_boards`."""
    images = _tiles()
    seams, anywhere, wrong = [], [], 0
    for k in range(max(first, 1), len(run.syncs) - 1):
        sync = run.syncs[k]
        t0, t1 = (sync, run.syncs[k + 1]) if span is None else (sync + span[0], sync + span[1])
        errors = [run.light(i, b, t0, t1, lsb) - images[i] for i, b in enumerate(boards)]
        anywhere.append(max(float(np.abs(e).max()) for e in errors))
        seams.append(max(float(np.abs(np.stack([a[:, -1], b[:, 0]])).max())
                         for a, b in zip(errors, errors[1:], strict=False)))
        wrong += sum(int(np.count_nonzero(np.round(e))) for e in errors)
    return max(seams), max(anywhere), wrong


#: The anchors compared, loops off: (the plane order, the anchor register). The frame starts on
#: the pulse at the order's position ``anchor``; the four-DMD paper's is the MSB plane of an
#: LSB-first frame.
ANCHORS = {"lsb_first_from_lsb": (PlaneOrder.LSB_FIRST, 0), "lsb_first_from_msb": (PlaneOrder.LSB_FIRST, 7),
           "msb_first_from_msb": (PlaneOrder.MSB_FIRST, 0), "msb_first_from_lsb": (PlaneOrder.MSB_FIRST, 7)}
#: Frames of each anchor's run.
ANCHOR_FRAMES = 40


def _span_ps(run):
    """The frame's light as every board shows it on average: from the sync pulse to its first
    clocking pulse and to its last (the final dark pulse), in ps, the mirrors' switching delay
    and half their ramp added."""
    per_board = run.frame_pulses()
    firsts = [f[0] - s for board in per_board for f, s in zip(board, run.syncs, strict=False) if len(f)]
    lasts = [f[-1] - s for board in per_board for f, s in zip(board, run.syncs, strict=False) if len(f)]
    motion = (CAMERA_DELAY + CAMERA_RAMP / 2) * BOARD_PERIOD_FS / 1000
    return float(np.mean(firsts)) + motion, float(np.mean(lasts)) + motion


def anchors():
    """The anchor register compared, loops off (the drift the anchor would share out), 8-plane
    frames: the seam error under a camera from one pulse to the next (the window holds the
    frame), over the frame's light as the boards show it on average (the camera's exposure set to
    the frame, triggered by the master), and the same lagging by 1 % of the frame. Table:
    ``build/sync_anchors.csv``."""
    figures, rows = {}, []
    lsb = _plan(8).params.lsb
    windows = ("pulse_to_pulse", "frame", "frame_lag_1pct")
    for name, (order, anchor) in ANCHORS.items():
        run = _run(8, ANCHOR_FRAMES, f"sync_anchor_{name}", trim=False, traces=True, order=order, anchor=anchor)
        t0, t1 = _span_ps(run)
        lag = (t1 - t0) / 100
        spans = dict(zip(windows, (None, (t0, t1), (t0 + lag, t1 + lag)), strict=True))
        boards = _boards(run)
        errors = {window: _seam_errors(run, boards, lsb, 1, span) for window, span in spans.items()}
        spread = float(run.spreads().max())
        rows.append([name, order.name, anchor, f"{spread:.3f}",
                     *[f"{errors[w][k]:.4f}" for w in windows for k in (0, 1)]])
        figures[f"sync.spread_ns_max_untrimmed_{name}"] = (spread, "ns, loops off",
                                                           TILED_SOURCE.format(name=f"sync_anchor_{name}"))
        for window, (seam, *_) in errors.items():
            figures[f"sync.seam_gray_error_lsb_max_untrimmed_{name}_{window}"] = (
                seam, "LSB, loops off", CAMERA_SOURCE.format(name=f"sync_anchor_{name}") + f", window {window}")
    write_table("sync_anchors", ["anchor", "order", "anchor_register", "spread_ns_max",
                                 *[f"{w}_{what}_lsb_max" for w in windows for what in ("seam", "tile")]], rows)
    names = list(ANCHORS)
    for window in windows:
        inputs = [f"sync.seam_gray_error_lsb_max_untrimmed_{n}_{window}" for n in names]
        seams = [figures[name][0] for name in inputs]
        # ties (to a thousandth of an LSB) go to the first
        figures[f"sync.best_anchor_{window}"] = (int(np.argmin(np.round(seams, 3))),
                                                 ", ".join(f"{i} {n}" for i, n in enumerate(names)),
                                                 "arithmetic: the anchor of the least of " + ", ".join(inputs))
    return figures


def _since_ns(run):
    """Per pulse of a frame, its mean time after the sync pulse (ns), over the run."""
    first = run.frame_pulses()[0]
    whole = [f for f in first if len(f) == len(first[0])]
    return np.mean([(f - s) / 1000 for f, s in zip(whole, run.syncs, strict=False)], axis=0)


def _chunk_rates(run):
    """Every board's rate (ppm) per :data:`CHUNK` frames: ``(chunks, boards)``."""
    return np.array([run.rates_ppm(f, min(f + CHUNK, len(run.syncs))) for f in range(0, len(run.syncs), CHUNK)])


def _table(run, spreads, rates):
    rows = []
    for k, first in enumerate(range(0, len(spreads), CHUNK)):
        part = spreads[first:first + CHUNK]
        rows.append([first, f"{(run.syncs[first] - run.syncs[0]) / 1e9:.3f}", f"{part.max():.3f}",
                     f"{part.mean():.3f}", f"{part[:, 0].max():.3f}", f"{part[:, -1].max():.3f}",
                     *[f"{r:.3f}" for r in rates[k]]])
    return rows


def run():
    long = _run(4, FRAMES, "sync_spread_4planes", trim=True)
    locked = long.locked_from()
    assert locked is not None, "the clock loops never locked"
    spreads = long.spreads()
    rates = _chunk_rates(long)
    rows = _table(long, spreads, rates)
    write_table("sync_spread", ["first_frame", "run_time_ms", "spread_ns_max", "spread_ns_mean",
                                "first_pulse_spread_ns_max", "last_pulse_spread_ns_max",
                                *[f"board{i}_ppm" for i in range(len(OSCILLATORS))]], rows)
    _plot(rows)
    after = spreads[locked:]
    hours = len(after) // 2
    source = TILED_SOURCE.format(name="sync_spread_4planes")
    figures = {
        "sync.boards": (len(OSCILLATORS), "boards", source),
        "sync.frames": (min(s["frames"] for s in long.status), "frames a board played", source),
        "sync.refused": (long.counts["not_ready"] + long.counts["early"], "pulses the master refused", source),
        "sync.ppm_max_model": (
            float(max(abs(o.error(t)) for o in OSCILLATORS for t in (0, long.syncs[-1] / 1e12)) * 1e6),
            "ppm, the crystals' largest error in the run",
            "model: the crystal models of run sync_spread_4planes (sim.rigs.tiled_rig.Oscillator), their largest "
            "error"),
        "sync.lock_frames": (locked, "frames until every board's loop stayed locked", source),
        "sync.spread_ns_max": (float(after.max()), "ns, every pulse of every frame once locked", source),
        "sync.spread_ns_max_first_half": (float(after[:hours].max()), "ns", source),
        "sync.spread_ns_max_second_half": (float(after[hours:].max()), "ns", source),
        "sync.spread_ns_max_acquiring": (float(spreads[:locked].max()), "ns, before the lock", source),
        "sync.locked_rate_difference_ppm_max": (float((rates.max(axis=1) - rates.min(axis=1))[1:].max()),
                                                "ppm between boards, per 500 frames once locked", source),
    }

    untrimmed = _run(4, UNTRIMMED_FRAMES, "sync_spread_4planes_untrimmed", trim=False)
    loose = untrimmed.spreads()
    loose_rates = _chunk_rates(untrimmed)
    difference = float((loose_rates.max(axis=1) - loose_rates.min(axis=1)).max()) * 1e-6
    sampling_ns = float(loose[:, 0].max())
    source = TILED_SOURCE.format(name="sync_spread_4planes_untrimmed")
    figures.update({
        "sync.spread_ns_max_untrimmed": (float(loose.max()), "ns, loops off", source),
        "sync.first_pulse_spread_ns_max_untrimmed": (sampling_ns, "ns (the boards' sampling of the pulse)", source),
    })

    # 8 planes: with the loops (every board's pins checked, the seams) and without (the check)
    eight = _run(8, EIGHT_FRAMES, "sync_spread_8planes", trim=True, traces=True)
    eight_locked = eight.locked_from()
    seam, anywhere, wrong = _seam_errors(eight, _boards(eight), _plan(8).params.lsb, eight_locked or 1)
    loose8 = _run(8, 100, "sync_spread_8planes_untrimmed", trim=False)
    predicted = sampling_ns + difference * float(_since_ns(loose8)[-1])
    lit = CAMERA_SOURCE.format(name="sync_spread_8planes")
    figures.update({
        "sync.spread_ns_max_8planes": (float(eight.spreads()[eight_locked:].max()), "ns, loops locked",
                                       TILED_SOURCE.format(name="sync_spread_8planes")),
        "sync.seam_gray_error_lsb_max": (seam, "LSB, window from pulse to pulse, either side of a seam", lit),
        "sync.tile_gray_error_lsb_max": (anywhere, "LSB, the same window, any pixel", lit),
        "sync.gray_levels_wrong": (wrong, "pixels of every frame once locked whose light, rounded, is not their level",
                                   lit),
        "sync.spread_ns_max_8planes_untrimmed": (float(loose8.spreads().max()), "ns, 100 frames, loops off",
                                                 TILED_SOURCE.format(name="sync_spread_8planes_untrimmed")),
        # (arithmetic on measured figures; ``_predicted_model``: a prediction, set against the one measured)
        "sync.spread_ns_max_8planes_untrimmed_predicted_model": (
            predicted, "ns, from the 4-plane run's figures",
            "arithmetic: sync.first_pulse_spread_ns_max_untrimmed + the largest rate difference between boards in "
            "run sync_spread_4planes_untrimmed x the time from the sync pulse to the last pulse in run "
            "sync_spread_8planes_untrimmed"),
    })

    # the DLP7000's 8-bit frame, for hours: the crystals' tolerance, or the loop's residual
    dlp7000 = schedule.plan(DMDS["dlp7000"], 400e6, depth=8)
    frame_ns = dlp7000.frame_cycles / 200e6 * 1e9
    residual = max(abs(e) for ppm in (PPM_TOLERANCE, -PPM_TOLERANCE)
                   for _, e in clock_trim.lock(dlp7000.frame_cycles, ppm, pulses=400)[200:]) * 1e-6
    figures.update({
        "sync.spread_ns_max_last_hour_extrapolated_model": (
            float(after.max()) + 2 * residual * frame_ns, "ns, DLP7000 8-bit frame, loops on",
            "model: sync.spread_ns_max plus twice the clock loop model's residual at +-100 ppm "
            "(sim.models.clock_trim_model.lock) over the schedule model's DLP7000 8-bit frame at 400 MHz"),
        "sync.spread_ns_max_last_hour_extrapolated_untrimmed_model": (
            2 * BOARD_PERIOD_FS / 1e6 + 2 * PPM_TOLERANCE * 1e-6 * frame_ns,
            "ns, DLP7000 8-bit frame, loops off, +-100 ppm",
            "model: two board cycles plus 200 ppm of the schedule model's DLP7000 8-bit frame at 400 MHz"),
        "sync.wall_s": (long.wall_s + untrimmed.wall_s + eight.wall_s + loose8.wall_s, "s of simulation",
                        TILED_SOURCE.format(name="sync_spread_4planes, sync_spread_4planes_untrimmed, "
                                                 "sync_spread_8planes and sync_spread_8planes_untrimmed")
                        + ", wall time"),
    })
    figures.update(anchors())
    return figures


def _plot(rows):
    plt = pyplot()
    fig, axes = plt.subplots(1, 2, figsize=(12, 4))
    t = [float(r[1]) for r in rows]
    for column, name in ((2, "largest spread"), (4, "first pulse (sampling)"), (5, "last pulse")):
        axes[0].plot(t, [float(r[column]) for r in rows], "o-", label=name)
    label(axes[0], "run time (ms)", "spread of the boards' clocking pulses (ns)",
          f"sync error per {CHUNK} frames, {len(OSCILLATORS)} boards, clock loops on")
    for i in range(len(OSCILLATORS)):
        axes[1].plot(t, [float(r[6 + i]) for r in rows], "o-", label=f"board {i}")
    label(axes[1], "run time (ms)", "clock error measured from the pulses (ppm)")
    save_figure(plt, fig, "sync_spread")


#: Frames of the DLP9500 run: its loops lock in about 160 pulses at its period (the model's).
DLP9500_FRAMES = 220
#: The steepest drift of the DLP9500 run's crystals (ppm/s).
DLP9500_RAMP = 10


def dlp9500():
    """Four boards of full DLP9500 geometry (four buses, DCLK 400 MHz, the store stand-in four
    words a cycle), 8-bit frames at the short settle timing of the small DMD's runs (a frame of
    150,000 cycles: TI's timing would make it five times longer), loops on: the spread once
    locked. The crystals are the small runs' but the drifting one ramps at 10 ppm/s (a
    temperature change of about a degree a second): at 1,000 ppm/s, 0.75 ppm a frame of this
    length, its loop keeps the master's rate but the integral term lags the ramp by more than
    the lock window, so the board takes the pulse a cycle late (a run of this bench showed it).
    About 15 minutes; not part of :func:`run`."""
    dmd = DMDS["dlp9500"]
    plan = schedule.plan(dmd, 400e6, depth=8, t_rst_s=20 / 200e6, t_settle_s=30 / 200e6, words_per_cycle=4)
    images = tiles(dmd, len(OSCILLATORS))
    oscillators = [replace(o, ramp_ppm_per_s=max(-DLP9500_RAMP, min(o.ramp_ppm_per_s, DLP9500_RAMP)))
                   for o in OSCILLATORS]
    run = run_tiled(dmd, plan.params, images, oscillators=oscillators, master=MASTER, frames=DLP9500_FRAMES,
                    master_period_cycles=master_period(plan.frame_cycles), name="sync_spread_dlp9500",
                    traces=False, trim=True, store_words=4)
    locked = run.locked_from()
    spreads = run.spreads()
    source = TILED_SOURCE.format(name="sync_spread_dlp9500") + ", full DLP9500 geometry"
    return {
        "sync.dlp9500_frames": (min(s["frames"] for s in run.status), "frames a board played", source),
        "sync.dlp9500_frame_cycles_model": (plan.frame_cycles, "dmd cycles a frame",
                                            "model: the schedule model's plan (spec.schedule.plan)"),
        "sync.dlp9500_lock_frames": (-1 if locked is None else locked, "frames until every loop stayed locked",
                                     source),
        "sync.dlp9500_spread_ns_max": (float(spreads[locked:].max()) if locked is not None else float("nan"),
                                       "ns, once locked", source),
        "sync.dlp9500_spread_ns_max_acquiring": (float(spreads[:locked].max()) if locked else float(spreads.max()),
                                                 "ns, before the lock", source),
        "sync.dlp9500_wall_s": (run.wall_s, "s of simulation", source + ", wall time"),
    }


if __name__ == "__main__":
    import sys
    benches = {"dlp9500": dlp9500, "anchors": anchors}
    for figure, (value, unit, *_source) in (benches[sys.argv[1]]() if sys.argv[1:] else run()).items():
        print(f"{figure:55s} {value:12.3f} {unit}")
