"""The ceiling of one-timeline plans (:mod:`spec.ceiling`): its stagger search against a brute
force over every stagger and pulse pair, and the ceiling above every plan the plan finder makes
and below the bound."""

import itertools

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from spec import ceiling, plan_search, schedule
from spec.facts import TEST_DMD
from spec.registers import ResetMode

#: RST_ACTIVE and settle scaled down so that the plans are made quickly.
FAST = {"t_rst_s": 20 / 200e6, "t_settle_s": 30 / 200e6}


def _brute_stagger(pulses, G, sep):
    """The smallest even stagger from ``sep`` on at which no pulses of two groups come closer
    than ``sep``, pair by pair."""
    s = sep + (sep & 1)
    while True:
        if all(abs(a + g * s - b - h * s) >= sep
               for g, h in itertools.permutations(range(G), 2) for a in pulses for b in pulses):
            return s
        s += 2


@settings(max_examples=200, deadline=None)
@given(st.lists(st.integers(1, 400), min_size=1, max_size=6), st.integers(2, 5), st.integers(1, 60))
def test_stagger_is_the_smallest_that_keeps_every_pulse_pair_apart(steps, G, sep):
    pulses = np.cumsum([0, *steps])
    assert ceiling._stagger(pulses, G, sep, 1 << 40) == _brute_stagger(list(pulses), G, sep)


def test_timeline_puts_a_dark_pulse_after_each_short_plane_and_the_last():
    # planes of 1, 4 and 2 units (1 and 2 shorter than the reload of 3), the last ending dark
    pulses, darks = schedule.timeline((0, 2, 1), 1, 3, 3)
    assert list(pulses) == [0, 1, 4, 8, 10] and darks == [True, False, False, True, False]
    # a plane as long as the reload hides the next plane's load
    assert list(schedule.timeline((0, 1), 3, 3, 3)[0]) == [0, 3, 9]


def _brute_frame(dmd, mode, depth, strict, lsbs, staggers):
    """The shortest frame of one-timeline plans on ``dmd`` at 200 MHz (one beat a cycle) under
    :data:`FAST` timing, by trying every order, LSB in ``lsbs`` and stagger in ``staggers``."""
    t_rst, t_settle = 20, 30
    size = {"GLOBAL": dmd.blocks, "QUAD": 4, "DUAL": 2, "SINGLE": 1}[mode]
    G, R = dmd.blocks // size, dmd.dclk_per_row
    reload = t_rst + t_settle + size * dmd.rows_per_block * R
    sep = t_rst if strict else R
    best = None
    for lsb in lsbs:
        if lsb < t_rst + t_settle + size * dmd.clear_row_cycles * R:
            continue
        for order in itertools.permutations(range(depth)):
            times, t = [], 0
            for j, e in enumerate(order):
                times.append(t)
                t += lsb * 2 ** e
                if j == depth - 1 or lsb * 2 ** e < reload:
                    times.append(t)
                    t += reload
            times = np.array(times)
            gaps = np.abs(times[:, None] - times[None, :])
            for s in staggers if G > 1 else [0]:
                if all((np.abs(gaps - k * s).min() >= sep) and (np.abs(times[:, None] - times[None, :] + k * s).min()
                                                                  >= sep) for k in range(1, G)):
                    frame = (G - 1) * s + t
                    best = frame if best is None else min(best, frame)
                    break
    return best


def test_ceiling_of_each_mode_is_the_brute_force_optimum():
    for mode in ("DUAL", "SINGLE", "GLOBAL"):
        for strict in (True, False):
            c = ceiling.ceiling_of_mode(TEST_DMD, 200e6, ResetMode[mode], depth=3, strict_rst=strict, **FAST)
            lsbs, staggers = range(2, 160, 2), range(2, 400, 2)
            assert c.lsb < lsbs[-1] - 20 and c.stagger < staggers[-1] - 20
            assert c.frame_cycles == _brute_frame(TEST_DMD, mode, 3, strict, lsbs, staggers), (mode, strict)


def test_no_plan_the_finder_makes_passes_the_ceiling():
    for strict in (True, False):
        top, each = ceiling.ceiling(TEST_DMD, 200e6, strict_rst=strict, workers=1, **FAST)
        assert top.frame_cycles == min(c.frame_cycles for c in each.values() if c is not None)
        assert top.rate_hz <= schedule.bound(TEST_DMD, 200e6, **FAST)
        found = plan_search.find(TEST_DMD, 200e6, strict_rst=strict, workers=1, **FAST)
        for c in found.candidates:
            if c.plan is None:
                continue
            mine = each[c.reset_mode] or each[ResetMode.GLOBAL]
            assert c.plan.frame_cycles >= mine.frame_cycles, (strict, c.describe())
