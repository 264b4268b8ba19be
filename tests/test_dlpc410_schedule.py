"""The schedule model on its own: plans, bounds, exact light per grey level, wide counters."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from gateware.registers import Registers
from sim.tb.plane_source import ramp_image
from spec import prng, schedule
from spec.facts import DMDS, TEST_DMD
from spec.registers import DURATION_BITS, LSB_BITS, PlaneOrder, ResetMode, Source
from spec.schedule.planner import _distance_to_nearest

XGA = DMDS["dlp7000"]


def test_bound_matches_derived_figure():
    # docs/bounds.md: 310.7 Hz at 200 MHz for 8-bit continuous-light PWM
    assert 305 < schedule.bound(XGA, 200e6) < 315
    assert schedule.bound(XGA, 200e6, depth=1) > 50 * schedule.bound(XGA, 200e6)


def test_paper_reading_bound_plan_and_equations():
    """The four-DMD paper's settle reading on the DLP9500 at 400 MHz: its equations give about
    450 Hz; its bound is 255 settle times (the flip spacing binds, not RST_ACTIVE and the clears);
    the plan under it keeps every pulse of a block a settle time apart (the rule model's ``flip``
    rule, on the model's commands) and lands between the two; TI's reading stays below 310 Hz."""
    d = DMDS["dlp9500"]
    assert 450 < schedule.paper_eq_rate_hz(d, 400e6) < 451
    assert schedule.bound(d, 400e6, reading="paper") == pytest.approx(1 / (255 * 8e-6))
    assert schedule.bound(d, 400e6) < 310
    plan = schedule.plan(d, 400e6, reading="paper", words_per_cycle=4, trigger_hold=True)
    p = plan.params
    assert (p.t_flip, p.lsb, p.t_settle) == (1600, 1600, schedule.PAPER_SETTLE_CYCLES)
    assert "flip spacing" in plan.binds
    assert schedule.paper_eq_rate_hz(d, 400e6) < plan.rate_hz < schedule.bound(d, 400e6, reading="paper")
    frame = schedule.Frame(0, 8)
    r = schedule.simulate(d, p, [frame], [schedule.ready_cycle(d, p, frame)])
    pulses = [t for t, kind, *_ in r.decoded() if kind == "pulse"]
    assert len(pulses) >= 8 and min(b - a for a, b in zip(pulses, pulses[1:], strict=False)) >= p.t_flip


def test_exponents():
    assert schedule.exponents(PlaneOrder.MSB_FIRST, None, 3) == [2, 1, 0]
    assert schedule.exponents(PlaneOrder.LSB_FIRST, None, 3) == [0, 1, 2]
    assert schedule.exponents(PlaneOrder.TABLE, (1, 2, 0), 3) == [1, 2, 0]
    with pytest.raises(AssertionError):
        schedule.exponents(PlaneOrder.TABLE, (1, 1, 0), 3)


@pytest.mark.parametrize("mode,strict,order", [
    (ResetMode.GLOBAL, True, PlaneOrder.MSB_FIRST),
    (ResetMode.GLOBAL, True, PlaneOrder.LSB_FIRST),
    (ResetMode.SINGLE, False, PlaneOrder.MSB_FIRST),
    (ResetMode.QUAD, True, PlaneOrder.LSB_FIRST),
])
def test_xga_every_level_exact(mode, strict, order):
    """Full XGA at 200 MHz with TI's timing: every grey level 0..255 integrates to its value."""
    plan = schedule.plan(XGA, 200e6, reset_mode=mode, strict_rst=strict, order=order)
    p = plan.params
    frame = schedule.Frame(0, 8)
    start = schedule.ready_cycle(XGA, p, frame)
    r = schedule.simulate(XGA, p, [frame], [start])
    assert r.late == 0 and r.accepted == [start]
    light = schedule.level_light(XGA, p, r, [ramp_image(XGA, 0)])[0]
    assert np.array_equal(light, ramp_image(XGA, 0).astype(np.int64) * p.lsb)
    # the settle rule binds the least significant plane in global mode
    if mode == ResetMode.GLOBAL:
        assert plan.binds.startswith("settle") and 250 < plan.rate_hz < schedule.bound(XGA, 200e6)


def test_binary_rates_against_ti_table():
    """Phased binary patterns at 400 MHz with a row every row cycle (two words per 200 MHz cycle):
    TI's table gives 32,552 Hz, one full load (768 rows of 16 DCLK) a pattern; here each group's
    pulse also takes a row cycle on the bus, so a pattern is the full load and a row cycle per
    group (quad, TI's strict reading: 32,383 Hz; one block a pulse, the loose reading: 31,888 Hz).
    Each plan keeps its rate: forty patterns back to back, no pulse late (a stagger of one
    group's load alone drifted, every pattern's loads ending a row cycle a group later, until
    pulses came late). Global ones: the table's neighbourhood of 22,614 Hz."""
    R = schedule.row_cycles(XGA, 2)
    for mode, strict in ((ResetMode.QUAD, True), (ResetMode.SINGLE, False)):
        phased = schedule.plan(XGA, 400e6, depth=1, chain=True, reset_mode=mode, strict_rst=strict,
                               words_per_cycle=2)
        groups = len(schedule.groups(XGA, mode))
        assert phased.frame_cycles == XGA.rows * R + groups * R and phased.binds.startswith("bus")
        p, fr = phased.params, schedule.Frame(0, 1)
        run = schedule.simulate(XGA, p, [fr], [schedule.ready_cycle(XGA, p, fr)], until=40 * phased.frame_cycles)
        starts = [t for t, g, *_ in run.pulses if g == 0]
        assert run.late == 0 and len(starts) >= 38 and set(np.diff(starts)) == {phased.frame_cycles}
    assert 32000 < schedule.plan(XGA, 400e6, depth=1, chain=True, reset_mode=ResetMode.QUAD,
                                 words_per_cycle=2).rate_hz < 32552
    glob = schedule.plan(XGA, 400e6, depth=1, chain=True, words_per_cycle=2)
    assert 22000 < glob.rate_hz < 23500


def test_memory_bandwidth_slows_rows():
    fast = schedule.plan(XGA, 200e6, depth=1, chain=True)
    slow = schedule.plan(XGA, 200e6, depth=1, chain=True, words_per_cycle=0.8)
    assert slow.params.row_period == 20 and slow.rate_hz < fast.rate_hz


def test_empty_blocks_are_cleared_not_loaded():
    occ = (0, 0xff, 0, 0)
    p = schedule.plan(TEST_DMD, 200e6, t_rst_s=20e-9 * 5, t_settle_s=30 * 5e-9).params
    r = schedule.simulate(TEST_DMD, p, [schedule.Frame(0, 8, occ)])
    rows = [a for _t, k, a in r.commands if k == "row"]
    clears = [a for _t, k, a in r.commands if k == "clear"]
    assert rows == list(range(24, 48)) and clears == [0, 2, 3]


def test_multi_second_frames_fit_the_counters():
    """A 10 s least significant plane at 400 MHz: fits the registers, every level exact."""
    lsb = schedule.even(int(10 * 400e6))
    assert lsb < 2 ** LSB_BITS and (lsb << 7) < 2 ** DURATION_BITS
    base = schedule.plan(XGA, 400e6).params
    p = schedule.Params(**{**base.__dict__, "lsb": lsb, "dark_gap": lsb})
    Registers.const(p.registers(XGA))   # every field fits
    frame = schedule.Frame(0, 8)
    start = schedule.ready_cycle(XGA, p, frame)
    r = schedule.simulate(XGA, p, [frame], [start])
    assert r.late == 0
    light = schedule.level_light(XGA, p, r, [ramp_image(XGA, 0)])[0]
    assert np.array_equal(light, ramp_image(XGA, 0).astype(np.int64) * lsb)


def test_prng_model_is_xorshift64():
    w = prng.words(1, 3)
    assert w[0] == 0x40822041 and len(set(w)) == 3
    assert prng.words(0, 1) == prng.words(prng.ZERO_SEED, 1)
    bits = np.unpackbits(np.array(prng.words(7, 4096), dtype="<u8").view(np.uint8))
    assert abs(bits.mean() - 0.5) < 0.01


def test_prng_patterns_follow_commands():
    p = schedule.plan(TEST_DMD, 200e6, depth=1, chain=True, source=Source.PRNG,
                      t_rst_s=100e-9, t_settle_s=150e-9).params
    start = schedule.ready_cycle(TEST_DMD, p, schedule.Frame(0, 1))
    r = schedule.simulate(TEST_DMD, p, [], [start], max_frames=3)
    shown = prng.shown_patterns(TEST_DMD, r.commands, 5)
    assert len(shown) >= 3 and not np.array_equal(shown[0], shown[1])


@pytest.mark.parametrize("dmd", [TEST_DMD, XGA, DMDS["dlp9500"]])
def test_pulse_encodings_decode_to_their_groups(dmd):
    """The model's block commands and the DLPC410 model's reading of them agree for every group."""
    from sim.models.dlpc410_model import Dlpc410
    controller = Dlpc410(dmd)
    for mode in ResetMode:
        for g, blocks in enumerate(schedule.groups(dmd, mode)):
            _kind, got = controller.block_command(*schedule.pulse_encoding(dmd, mode, g))
            assert got == tuple(blocks)


@pytest.mark.parametrize("mode,strict,order", [
    (ResetMode.GLOBAL, True, PlaneOrder.MSB_FIRST),
    (ResetMode.GLOBAL, True, PlaneOrder.LSB_FIRST),
    (ResetMode.QUAD, True, PlaneOrder.MSB_FIRST),
    (ResetMode.DUAL, True, PlaneOrder.LSB_FIRST),
    (ResetMode.SINGLE, False, PlaneOrder.MSB_FIRST),
    (ResetMode.SINGLE, True, PlaneOrder.LSB_FIRST),
])
def test_fastest_plans_obey_every_rule_at_the_facts_timing(mode, strict, order):
    """The shortest legal plan at the facts' RST_ACTIVE and settle times (not scaled down),
    played through the rule-checking DLPC410 model: no rule broken, and the camera model (4 us
    crossover) sees every grey level exactly in a window holding the frame."""
    p = schedule.plan(TEST_DMD, 200e6, reset_mode=mode, strict_rst=strict, order=order).params
    played_exactly(TEST_DMD, p)


def played_exactly(dmd, p):
    """One 8-bit ramp frame of ``p`` through the rule model at the facts' timing (raises on
    any rule break); the camera sees every grey level exactly."""
    from sim.models.camera_model import Camera, to_lsb
    from sim.models.dlpc410_driver import Driver, play_schedule
    from sim.models.dlpc410_model import Dlpc410

    frame = schedule.Frame(0, 8)
    result = schedule.simulate(dmd, p, [frame], [schedule.ready_cycle(dmd, p, frame)])
    assert result.late == 0
    model = Dlpc410(dmd, init_cycles=16, strict_rst_active=p.strict_rst)
    assert model.rst_active_cycles <= p.t_rst - schedule.RST_MARGIN
    driver = Driver(dmd)
    driver.start(16)
    image = ramp_image(dmd, 0)
    play_schedule(driver, dmd, p, result, {0: image}, model.ecp2_cycles + 16)
    model.run(driver.items)
    pulses = [c.cycle for c in model.log if c.kind == "pulse"]
    assert len(pulses) == len(result.pulses) >= 9 * len(schedule.groups(dmd, p.reset_mode))
    camera = Camera(model)
    seen = to_lsb(camera.image(pulses[0], pulses[-1] + camera.ramp), p.lsb)
    assert np.array_equal(seen[:, :dmd.visible_columns], image[:, :dmd.visible_columns])


@given(st.lists(st.integers(-10**6, 10**6), min_size=1, max_size=40),
       st.lists(st.integers(-2 * 10**6, 2 * 10**6), max_size=40))
def test_distance_to_nearest_equals_every_pair_compared(values, points):
    """The spread search's pulse spacing test: the distance from each stagger to the nearest
    pulse difference, from its neighbours in order, equals the least over every difference."""
    values, points = np.unique(values), np.array(points, np.int64)
    brute = np.abs(values[None, :] - points[:, None]).min(axis=1) if len(points) else points
    assert np.array_equal(_distance_to_nearest(values, points), brute)


@pytest.mark.parametrize("mode", [ResetMode.QUAD, ResetMode.DUAL])
def test_phased_pwm_spreads_groups_on_xga(mode):
    """Phased 8-bit PWM on the DLP7000 (strict RST_ACTIVE): groups spread apart beat the LSB
    lattice (189.5 Hz quad, 66.8 Hz dual), the plan says the load queue order binds, and the
    frame obeys every rule with every grey level exact."""
    plan = schedule.plan(XGA, 200e6, reset_mode=mode)
    p = plan.params
    assert "load queue order" in plan.binds
    assert plan.rate_hz > 250
    assert p.dark_gap % p.lsb and p.stagger > p.t_rst
    played_exactly(XGA, p)
