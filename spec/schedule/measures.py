"""The schedule's measures: what a plan shows and how fast it plays, from runs of the model.

Each runs :func:`.model.simulate` and reads its :class:`.terms.Result`: the light per pixel
(:func:`level_light`), the first cycle a trigger is obeyed (:func:`ready_cycle`), whether a plan
makes no pulse late (:func:`on_time`), its shortest period (:func:`frame_period`) and frames
triggered back to back (:func:`back_to_back`). The planner checks its plans with them.
"""

from dataclasses import replace

import numpy as np

from ..registers import PlaneOrder
from .model import simulate
from .terms import groups

__all__ = ["level_light", "ready_cycle", "on_time", "frame_period", "back_to_back"]


def level_light(dmd, p, result, images):
    """On-cycles per pixel from the model's pulses (a gated plane's: its light's on-time):
    {frame index: (rows, columns) int array},
    ``images[i]`` being the 8-bit image of the i-th frame taken (the planes it shows:
    :meth:`Frame.stored_plane`)."""
    group_blocks = groups(dmd, p.reset_mode)
    light = {}
    by_group = {}
    for (t, g, kind, fi, e) in result.pulses:
        by_group.setdefault(g, []).append((t, kind, fi, e))
    for g, seq in by_group.items():
        rows = slice(group_blocks[g][0] * dmd.rows_per_block, (group_blocks[g][-1] + 1) * dmd.rows_per_block)
        for (t, kind, fi, e), (t2, *_rest) in zip(seq, seq[1:], strict=False):
            if kind != "plane":
                continue
            img = np.asarray(images[fi], dtype=np.int64)
            bit = (img[rows] >> result.shown[fi].stored_plane(e)) & 1
            acc = light.setdefault(fi, np.zeros(img.shape, dtype=np.int64))
            acc[rows] += bit * (p.light_times[e] if p.gated(e) else t2 - t)
    return light


def ready_cycle(dmd, p, fr):
    """First cycle at which a trigger strobe is obeyed after initialisation."""
    r = simulate(dmd, p, [fr])
    return max(group.loaded_at for group in r.groups)


def on_time(dmd, p, fr):
    """The frame ``fr`` played under ``p`` (three of them, chained) has no pulse late: every
    plane is shown at its length."""
    n = _chained(dmd, p, fr)
    r = simulate(dmd, p, [replace(fr, ready=0)] * n, [ready_cycle(dmd, p, fr)], max_frames=max(2, n - 1))
    return r.late == 0


def _chained(dmd, p, fr):
    """Frames a chained check plays: three, or for patterns enough that a load falling behind
    by a row cycle a pattern would make a pulse late (every group's load drifting past its
    slack)."""
    if not p.chain:
        return 1
    return 3 if fr.depth > 1 else 4 + 2 * len(groups(dmd, p.reset_mode))


def frame_period(dmd, p, fr):
    """Shortest trigger-to-trigger period (triggered) or frame period (chained)."""
    if p.chain:
        n = max(4, _chained(dmd, p, fr))
        r = simulate(dmd, p, [fr] * n, [ready_cycle(dmd, p, fr)], max_frames=n - 1)
        return r.frame_starts[-1] - r.frame_starts[-2]
    first = ready_cycle(dmd, p, fr)
    if p.order != PlaneOrder.GROUPS:
        # trigger as soon as ready: a second strobe is obeyed once every group, its frame
        # played, is loaded again (the last thing each group does)
        r = simulate(dmd, p, [fr], [first])
        return max(group.loaded_at for group in r.groups) - first
    # GROUPS: the trigger after a trigger's frame waits for less than the first one (group 0's
    # load, not every group's): the period between the second and third
    accepted = back_to_back(dmd, p, fr, 3).accepted
    return accepted[2] - accepted[1]


def back_to_back(dmd, p, fr, n):
    """``n`` frames ``fr`` triggered back to back under ``p``, from the first cycle every group
    is loaded, each strobe after the first held until the groups are ready for it: the
    :class:`Result` (``accepted``: the ``n`` triggers' cycles)."""
    held, strobes = replace(p, trigger_hold=True), [ready_cycle(dmd, p, fr)]
    while True:
        last = len(strobes) == n
        r = simulate(dmd, held, [fr], strobes if last else [*strobes, strobes[-1] + 1])
        if last:
            return r
        strobes.append(r.accepted[-1])
