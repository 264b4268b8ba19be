"""Host figures: the rounding a frame's bit depth leaves, measured through the schedule model.

For each bit depth ``d``, a scene whose grey levels are the values a ``d``-bit frame shows, as an
8-bit renderer writes them (rounded to whole LSB): the host (:func:`host.levels.quantise`, the
default tolerance) picks the depth and rounds; the schedule model (the sequencer's cycle-exact
twin) then shows the bytes sent at that depth, and the error is what it shows, in 8-bit LSB of
full scale (light over the frame's full-scale light, times 255), against the target.
``host.rounding_error_lsb_max_model`` is the largest such error over every depth (``_model``: what
the schedule model shows); ``host.depth_chosen_errors`` counts scenes sent at another depth than
the one they were made at. The default scene forced to each depth gives
``host.rounding_error_lsb_scene_depth<d>_model``: half a step of that depth at most, where cutting
the low bits would leave a whole step.
"""

import time

import numpy as np

from host import levels
from sim.rigs.scene import default_scene
from spec import schedule
from spec.facts import DMDS

DMD = DMDS["dlp7000"]
#: Where the figures come from (:mod:`flow.bench`).
SOURCE_SHOWN = ("model: host.levels.quantise's bytes as the schedule model (spec.schedule) shows them, "
                "DLP7000, against the target")
SOURCE_HOST = "host: host.levels.quantise on the default scene, in Python"


def shown_by_model(data, depth, dmd=DMD):
    """What the schedule model shows for the bytes ``data`` at ``depth``: 8-bit LSB of full scale."""
    p = schedule.plan(dmd, 200e6, depth=depth).params
    frame = schedule.Frame(0, depth)
    result = schedule.simulate(dmd, p, [frame], [schedule.ready_cycle(dmd, p, frame)], max_frames=1)
    light = schedule.level_light(dmd, p, result, [data])[0]
    return light * (levels.FULL_SCALE / (p.lsb * ((1 << depth) - 1)))


def scene_at(depth, scene):
    """``scene`` posterised to the values a ``depth``-bit frame shows, rounded to 8 bits."""
    values = np.round(levels.shown(np.arange(1 << depth), depth)).astype(np.uint8)
    return values[levels.levels(scene, depth)]


def run():
    scene = default_scene(1, DMD.rows, DMD.columns)[0]
    figures, worst, wrong = {}, 0.0, 0
    for depth in levels.DEPTHS:
        target = scene_at(depth, scene)
        out = levels.quantise(target)
        error = float(np.abs(shown_by_model(out.data, out.depth) - target).max())
        worst = max(worst, error)
        wrong += out.depth != depth
        figures[f"host.rounding_error_lsb_depth{depth}_model"] = (error, "LSB", SOURCE_SHOWN)
        forced = levels.quantise(scene, depth)
        figures[f"host.rounding_error_lsb_scene_depth{depth}_model"] = (
            float(np.abs(shown_by_model(forced.data, depth) - scene).max()), "LSB", SOURCE_SHOWN)
    t0 = time.perf_counter()
    chosen = levels.quantise(scene)
    seconds = time.perf_counter() - t0
    return {
        "host.rounding_error_lsb_max_model": (worst, "LSB", "arithmetic: the largest of "
                                              + ", ".join(f"host.rounding_error_lsb_depth{d}_model"
                                                          for d in levels.DEPTHS)),
        "host.depth_chosen_errors": (wrong, "scenes", "host: host.levels.quantise's depth for each depth's scene"),
        "host.scene_depth": (chosen.depth, "bits", SOURCE_HOST),
        "host.quantise_ms_xga": (seconds * 1e3, "ms", SOURCE_HOST + ", timed"),
        **figures,
    }


if __name__ == "__main__":
    for name, (value, unit, *_source) in run().items():
        print(f"{name:44} {value:.6g} {unit}")
