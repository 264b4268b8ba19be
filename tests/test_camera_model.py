"""The camera model on binary-weighted PWM played through the DLPC410 model on TEST_DMD.

A window that holds the whole frame integrates every grey level 0-255 to exactly its value in
LSB units (global and phased pulses, MSB and LSB first, with a mirror ramp); a misaligned window
gives the error an independent integration of the same schedule predicts.
"""

import numpy as np
import pytest

from sim.models import bitplane_model as bitplane
from sim.models.camera_model import Camera, ramp_integral, to_lsb
from sim.models.dlpc410_driver import Driver
from sim.models.dlpc410_model import Dlpc410, timing_cycles
from spec.facts import TEST_DMD

T = timing_cycles(200e6)
R, S = T["rst_active_cycles"], T["settle_cycles"]
RAMP = T["crossover_cycles"]
DELAY = 150
INIT = 20
GAP = R + 2                    # phased: block pulses an even gap apart, RST_ACTIVE fallen
LSB = {"global": 2800, "phased": 3 * GAP + R + 1 + S + 2 * TEST_DMD.rows + 101}   # even
ORDERS = {"msb": list(range(7, -1, -1)), "lsb": list(range(8))}


def grey_image():
    """Every grey level 0-255, in every block and at both ends of a row."""
    levels = np.arange(TEST_DMD.rows * TEST_DMD.columns) % 256
    shuffled = np.random.default_rng(0).permutation(levels).astype(np.uint8)
    return shuffled.reshape(TEST_DMD.rows, TEST_DMD.columns)


def play(image, order, mode):
    """One PWM frame of ``image``: plane ``k`` shown for ``2**k * LSB`` cycles in ``order``,
    then every block cleared and pulsed dark. Returns the model and, per block, the cycles its
    mirrors were pulsed (one per plane, then the dark pulse), as the driver scheduled them."""
    lsb = LSB[mode]
    dmd = TEST_DMD
    model = Dlpc410(dmd, init_cycles=INIT)
    d = Driver(dmd)
    d.start(INIT)
    bits = bitplane.planes(image)
    offsets = [b * GAP if mode == "phased" else 0 for b in range(dmd.blocks)]
    pulses = [[] for _ in range(dmd.blocks)]
    d.load(bits[order[0]])
    start = d.cycle
    for i, k in enumerate([*order, None]):
        base = start + sum(2 ** j for j in order[:i]) * lsb
        if mode == "global":
            d.wait_until(base)
            assert d.pulse("global") == base
        else:
            for b in range(dmd.blocks):
                d.wait_until(base + offsets[b])
                assert d.pulse("single", b) == base + offsets[b]
        for b in range(dmd.blocks):
            pulses[b].append(base + offsets[b])
        if k is None:
            break
        d.wait_until(base + offsets[-1] + R + 1 + S)     # the last pulsed block has settled
        if i + 1 < len(order):
            d.load(bits[order[i + 1]])
        else:
            for b in range(dmd.blocks):
                d.clear(b)
        assert d.cycle <= base + 2 ** k * lsb, "the schedule does not fit the plane"
    model.run(d.items)
    assert model.pulse_cycles == pulses
    return model, pulses


def expected_light(image, order, pulses, t0, t1, ramp, delay):
    """Independent integral: per pixel, the mirror's light is a piecewise linear curve through
    knots at every change (ramp from ``start + delay`` to ``start + delay + ramp``; a step when
    ``ramp`` is 0), integrated exactly by the midpoint rule between the knots and the window's
    ends (the curve is linear there)."""
    rpb = TEST_DMD.rows_per_block
    out = np.zeros(image.shape)
    for r in range(image.shape[0]):
        starts = pulses[r // rpb]
        for g in np.unique(image[r]):
            states = [(int(g) >> k) & 1 for k in order] + [0]
            xs, ys, cur = [t0 - 1], [0.0], 0
            for s, new in zip(starts, states, strict=True):
                if new != cur:
                    xs += [s + delay, s + delay + ramp]
                    ys += [cur, new]
                    cur = new
            xs.append(max(t1, xs[-1]) + 1)
            ys.append(cur)
            grid = np.array(sorted({t0, t1, *[x for x in xs if t0 < x < t1]}), dtype=np.float64)
            mid = (grid[1:] + grid[:-1]) / 2
            out[r, image[r] == g] = np.sum(np.diff(grid) * np.interp(mid, xs, ys))
    return out


@pytest.mark.parametrize("mode", ["global", "phased"])
@pytest.mark.parametrize("order", ["msb", "lsb"])
def test_every_grey_level_exact(mode, order):
    image = grey_image()
    model, pulses = play(image, ORDERS[order], mode)
    camera = Camera(model, ramp_cycles=RAMP, delay_cycles=DELAY)
    t0, t1 = pulses[0][0] - 10, pulses[-1][-1] + DELAY + RAMP + 10
    got = to_lsb(camera.image(t0, t1), LSB[mode])
    assert got.shape == image.shape
    assert np.abs(got - image).max() < 1e-9
    assert set(np.round(got).astype(int).ravel()) == set(range(256))


@pytest.mark.parametrize("order", ["msb", "lsb"])
@pytest.mark.parametrize("ramp", [0, RAMP])
def test_misaligned_window_error(ramp, order):
    """A window that starts late and ends early: the camera's error in LSB equals the
    independent integral's."""
    image = grey_image()
    model, pulses = play(image, ORDERS[order], "global")
    camera = Camera(model, ramp_cycles=ramp, delay_cycles=DELAY)
    lsb = LSB["global"]
    t0, t1 = pulses[0][0] + 1234, pulses[0][-1] - 567
    got = to_lsb(camera.image(t0, t1), lsb)
    want = to_lsb(expected_light(image, ORDERS[order], pulses, t0, t1, ramp, DELAY), lsb)
    assert np.abs(got - want).max() < 1e-6
    err = got - image
    assert err.min() < -0.4, "the misaligned window must lose light"
    # the largest loss is the white pixel's: the cut-off ends of the frame
    assert err[image == 255].min() == pytest.approx((1234 + 567) / -lsb, abs=1e-9)


@pytest.mark.parametrize("phase", [0, 1, 2, 3])
def test_window_through_ramps(phase):
    """Window edges inside mirror transitions (the ramp's partial integral), with phased pulses:
    each block's ramps fall elsewhere in the window."""
    image = grey_image()
    order = ORDERS["msb"]
    model, pulses = play(image, order, "phased")
    camera = Camera(model, ramp_cycles=RAMP, delay_cycles=DELAY)
    t0 = pulses[phase][0] + DELAY + 300
    t1 = pulses[phase][3] + DELAY + 170                # inside the ramp of plane 4 in block `phase`
    got = camera.image(t0, t1)
    want = expected_light(image, order, pulses, t0, t1, RAMP, DELAY)
    assert np.abs(got - want).max() < 1e-6
    # the window's end cuts the ramp of plane 4 (bit 4 off -> on or on -> off) in block `phase`
    rows = slice(phase * 24, (phase + 1) * 24)
    assert not np.allclose(got[rows] % 1, 0)


def test_window_inside_a_plane_and_before_any_pulse():
    image = grey_image()
    model, pulses = play(image, ORDERS["msb"], "global")
    camera = Camera(model, ramp_cycles=RAMP, delay_cycles=DELAY)
    msb_on = pulses[0][0] + DELAY + RAMP
    got = camera.image(msb_on, msb_on + 1000)
    assert np.array_equal(got, 1000.0 * (image >> 7))
    assert not camera.image(0, pulses[0][0] + DELAY).any()
    after = pulses[0][-1] + DELAY + RAMP
    assert not camera.image(after, after + 10**6).any()


def test_ramp_integral():
    x = np.array([-5, 0, 2, 4, 9])
    assert list(ramp_integral(x, 4)) == [0, 0, 0.5, 2, 7]
    assert list(ramp_integral(x, 0)) == [0, 0, 2, 4, 9]
