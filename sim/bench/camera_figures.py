"""A camera out of step with the projector: grey error against the misalignment of its window.

The experiment of the seed design (2014): a camera integrates exactly one frame period, but its
window starts before (leads) or after (lags) the frame by 0 to 100 % of a frame. The projector
plays three stored frames back to back, triggered at the frame rate: black, a ramp holding every
grey level, black (a target that appears for one frame). The pins come from the sequencer's
generated Verilog on the test DMD (:mod:`sim.rigs.seq_rig`), the mirrors from the rule-checking
DLPC410 model, the light from the camera model; the error of each grey level is what the camera
sees less the level, in LSB. With MSB first the most significant plane fills the first half of
the frame, so a lagging window loses up to 128 LSB from every level of 128 and up while the
levels below lose only their low planes: the error jumps at 128. With LSB first the jump moves to
a leading window. The interleaved order (``7 1 6 2 5 3 4 0``, :func:`spec.plan_search.interleaved`,
which the plan finder picks for phased plans) is measured beside them.
``build/camera_misalignment.csv`` and ``.png``.
"""

import numpy as np

from sim.bench.tables import label, pyplot, save_figure, write_table
from sim.models.camera_model import Camera, to_lsb
from sim.rigs.seq_rig import run_rig
from sim.tb.seq_sim import CAMERA_DELAY, CAMERA_RAMP
from spec import plan_search, schedule
from spec.facts import TEST_DMD
from spec.registers import TriggerMode

__all__ = ["misalignment", "run", "SHIFTS_PCT", "SHOWN_PCT", "worst_by_shift", "write_one_curve"]

#: Window start minus the ramp frame's first pulse, in % of the frame period (- leads, + lags).
SHIFTS_PCT = tuple(sorted({*range(-100, 101, 5), -1, 1}))
#: The shifts the figures name (the plot shows those of 10 % and more).
SHOWN_PCT = (-50, -10, -1, 1, 10, 50)


def misalignment(order, shifts=SHIFTS_PCT, *, name=None):
    """Per shift (% of a frame), the mean error (LSB) of each grey level 0..255, for the plane
    ``order`` (``TABLE``: the interleaved order): ``{shift: array of 256}``."""
    dmd = TEST_DMD
    plan = schedule.plan(dmd, 200e6, depth=8, **plan_search.order_kwargs(order, 8), t_rst_s=20 / 200e6,
                         t_settle_s=30 / 200e6)
    p = plan.params
    p.trigger, p.trigger_hold, p.period = TriggerMode.PERIODIC, True, plan.frame_cycles
    # every grey level 0..255 on the 128 columns: odd rows hold the upper half
    rows, columns = np.indices((dmd.rows, dmd.columns))
    ramp = ((columns + 128 * (rows % 2)) & 255).astype(np.uint8)
    images = {0: np.zeros_like(ramp), 1: ramp}
    frames = [(slot, 8, 0, 1) for slot in (0, 1, 0)]
    until = 4 * p.period
    run = run_rig(dmd, p, frames, images, cycles=until, name=name or f"camera_{order.name.lower()}")
    starts = [first for first, _last in run.frames()]
    assert len(starts) >= 3, f"three frames expected, got {len(starts)}"
    period = starts[2] - starts[1]
    camera = Camera(run.model, ramp_cycles=CAMERA_RAMP, delay_cycles=CAMERA_DELAY)
    levels = np.arange(256)
    out = {}
    for pct in shifts:
        t0 = starts[1] + round(pct * period / 100)
        seen = to_lsb(camera.image(t0, t0 + period), p.lsb)
        error = seen - ramp
        out[pct] = np.array([error[ramp == g].mean() for g in levels])
    return out


def _write(curves):
    write_table("camera_misalignment", ["order", "shift_pct_of_frame", *[f"error_lsb_grey_{g}" for g in range(256)]],
                [[order, pct, *[f"{e:.3f}" for e in errors]]
                 for order, by_shift in curves.items() for pct, errors in by_shift.items()])
    plt = pyplot()
    fig, axes = plt.subplots(1, len(curves) + 1, figsize=(5 * (len(curves) + 1), 4))
    for k, (order, by_shift) in enumerate(curves.items()):
        for pct in (p for p in SHOWN_PCT if abs(p) >= 10):
            axes[k].plot(range(256), by_shift[pct], label=f"{pct:+d} %")
        axes[k].axvline(128, color="grey", alpha=0.3)
        label(axes[k], "grey level", "camera error (LSB)", f"{order}: error against grey level",
              legend_title="window start (% of a frame)")
        axes[-1].plot(list(by_shift), [np.abs(e).max() for e in by_shift.values()], "o-", label=order)
    label(axes[-1], "window start - frame start (% of a frame; - leads, + lags)", "max |error| (LSB)",
          "largest error against misalignment")
    save_figure(plt, fig, "camera_misalignment")


def worst_by_shift(by_shift, shown=SHOWN_PCT):
    """The largest error (LSB, absolute) of the aligned window and of each shift ``shown``, by the
    part of a figure's name that says when the window starts: ``aligned``, ``lag_<p>pct``,
    ``lead_<p>pct``."""
    out = {"aligned": float(np.abs(by_shift[0]).max())}
    for pct in shown:
        out[f"lag_{pct}pct" if pct > 0 else f"lead_{-pct}pct"] = float(np.abs(by_shift[pct]).max())
    return out


def write_one_curve(name, by_shift, title):
    """``build/<name>.csv`` and ``.png`` of one mode's experiment (``{shift: error of each grey
    level}``): the error against the grey level at the shifts of 10 % and more, and the largest
    error against the shift."""
    levels = len(next(iter(by_shift.values())))
    write_table(name, ["shift_pct_of_frame", *[f"error_lsb_grey_{g}" for g in range(levels)]],
                [[pct, *[f"{e:.3f}" for e in errors]] for pct, errors in by_shift.items()])
    plt = pyplot()
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    for pct in (p for p in SHOWN_PCT if abs(p) >= 10 and p in by_shift):
        axes[0].plot(range(levels), by_shift[pct], label=f"{pct:+d} %")
    label(axes[0], "grey level", "camera error (LSB)", f"{title}: error against grey level",
          legend_title="window start (% of a frame)")
    axes[1].plot(list(by_shift), [np.abs(e).max() for e in by_shift.values()], "o-", label=title)
    label(axes[1], "window start - frame start (% of a frame; - leads, + lags)", "max |error| (LSB)",
          "largest error against misalignment")
    save_figure(plt, fig, name)


#: Where the camera figures come from (:mod:`flow.bench`).
SOURCE_RIG = ("gateware: sequencer Verilog (sim.rigs.seq_rig), test DMD, three frames triggered at the frame rate; "
              "pins through the DLPC410 rule model, light through the camera model")


def run():
    curves = {name.lower(): misalignment(order, name=f"camera_{name.lower()}")
              for name, order in plan_search.ORDER_NAMES.items()}
    _write(curves)
    figures = {}
    for order, by_shift in curves.items():
        figures[f"cam.aligned_error_lsb_max_{order}"] = (float(np.abs(by_shift[0]).max()), "LSB", SOURCE_RIG)
        for pct in SHOWN_PCT:
            when = f"lag_{pct}pct" if pct > 0 else f"lead_{-pct}pct"
            errors = by_shift[pct]
            figures[f"cam.{when}_error_lsb_max_{order}"] = (float(np.abs(errors).max()), "LSB", SOURCE_RIG)
            figures[f"cam.{when}_jump_at_128_lsb_{order}"] = (float(errors[128] - errors[127]), "LSB", SOURCE_RIG)
    # the plane order with the smallest worst error a 1 % misalignment either way leaves:
    # 0 MSB first, 1 LSB first, 2 interleaved
    inputs = {order: [f"cam.{w}_1pct_error_lsb_max_{order}" for w in ("lag", "lead")] for order in curves}
    worst = {order: max(figures[name][0] for name in names) for order, names in inputs.items()}
    figures["cam.best_order_1pct"] = (list(curves).index(min(worst, key=worst.get)),
                                      "0 msb_first, 1 lsb_first, 2 interleaved",
                                      "arithmetic: the order of the least of the larger of "
                                      + ", ".join(" and ".join(names) for names in inputs.values()))
    return figures


if __name__ == "__main__":
    for figure, (value, unit, *_source) in run().items():
        print(f"{figure:50s} {value:10.3f} {unit}")
