"""Bit depth and rounding (:mod:`host.levels`) against a brute-force numpy oracle, and against
the light the schedule model says a frame of that depth sends."""

import numpy as np
import pytest

from host import levels
from spec import schedule
from spec.facts import TEST_DMD


def nearest(target, depth):
    """Oracle: every level's shown value tried, the closest kept."""
    shown = np.arange(2 ** depth) * 255.0 / (2 ** depth - 1)
    distance = np.abs(np.asarray(target, np.float64)[..., None] - shown)
    return distance.argmin(axis=-1), distance.min(axis=-1)


@pytest.mark.parametrize("depth", levels.DEPTHS)
def test_levels_are_the_nearest(depth):
    rng = np.random.default_rng(depth)
    targets = np.concatenate([np.arange(256.0), rng.uniform(0, 255, 2000)])
    want, distance = nearest(targets, depth)
    got = levels.levels(targets, depth)
    assert np.array_equal(got, want)
    assert np.allclose(np.abs(levels.shown(got, depth) - targets), distance)
    # half a step at most: 127.5 LSB at depth 1, 0.5 at depth 8
    assert distance.max() <= 127.5 / (2 ** depth - 1) + 1e-9


@pytest.mark.parametrize("depth", levels.DEPTHS)
def test_bytes_carry_the_level_in_their_top_bits(depth):
    q = np.arange(2 ** depth)
    data = levels.encode(q, depth)
    assert np.array_equal(data >> (8 - depth), q)
    # read as an 8-bit image, within one LSB below what is shown
    error = levels.shown(q, depth) - data
    assert error.min() >= 0 and error.max() < 1


def test_truncation_would_lose_a_dim_target():
    """The case rounding fixes: at depth 4 a target of 15 on black is level 1 (17 LSB), where
    the top bits of 15 are 0 (black)."""
    image = np.zeros((4, 4), np.uint8)
    image[1:3, 1:3] = 15
    out = levels.quantise(image, 4)
    assert out.levels.max() == 1 and (out.data >> 4).max() == 1
    assert out.error_lsb == pytest.approx(2.0)
    assert (image >> 4).max() == 0


def test_depth_chosen_is_the_smallest_within_tolerance():
    rng = np.random.default_rng(5)
    for depth in levels.DEPTHS:
        # an image drawn from the values a frame of this depth shows, as an 8-bit renderer writes them
        values = np.round(np.arange(2 ** depth) * 255 / (2 ** depth - 1)).astype(np.uint8)
        image = rng.choice(values, size=(24, 32))
        image[0, :len(values[:32])] = values[:32]
        if depth == 8:
            image[1, :] = 128
        out = levels.quantise(image)
        # the oracle: the errors of every depth, the smallest that is within half an LSB
        worst = {d: nearest(np.unique(image), d)[1].max() for d in levels.DEPTHS}
        assert out.depth == min(d for d in levels.DEPTHS if worst[d] <= 0.5) == depth
        assert out.error_lsb == pytest.approx(worst[depth]) and out.error_lsb <= 0.5
    image = rng.integers(0, 256, (24, 32), dtype=np.uint8)
    loose = levels.quantise(image, tolerance=20)
    assert loose.depth == min(d for d in levels.DEPTHS if nearest(image, d)[1].max() <= 20)
    assert loose.error_lsb == pytest.approx(nearest(image, loose.depth)[1].max())


def test_real_targets_and_bad_input():
    out = levels.quantise(np.array([[0.0, 127.25, 255.0]]))
    assert out.depth == 8 and out.error_lsb == pytest.approx(0.25)
    with pytest.raises(ValueError, match="0..255"):
        levels.quantise(np.array([[-1.0, 3.0]]))
    with pytest.raises(ValueError, match="bit depth 9"):
        levels.quantise(np.zeros((2, 2), np.uint8), 9)


@pytest.mark.parametrize("depth", [1, 3, 6])
def test_schedule_model_shows_the_level(depth):
    """The bytes sent, shown by the schedule model (the sequencer's cycle-exact twin) at this
    depth: each pixel's light is ``level * lsb`` cycles, so the value in 8-bit LSB of full scale
    is the one :func:`levels.shown` gives and the error the one reported."""
    dmd = TEST_DMD
    rng = np.random.default_rng(depth)
    target = rng.uniform(0, 255, (dmd.rows, dmd.columns))
    out = levels.quantise(target, depth)
    p = schedule.plan(dmd, 200e6, depth=depth).params
    frame = schedule.Frame(0, depth)
    result = schedule.simulate(dmd, p, [frame], [schedule.ready_cycle(dmd, p, frame)], max_frames=1)
    light = schedule.level_light(dmd, p, result, [out.data])[0]
    assert np.array_equal(light, out.levels.astype(np.int64) * p.lsb)
    seen = light / (p.lsb * (2 ** depth - 1)) * 255
    assert np.abs(seen - target).max() == pytest.approx(out.error_lsb)
