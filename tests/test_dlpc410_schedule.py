"""The schedule model on its own: plans, bounds, exact light per grey level, wide counters."""

import numpy as np
import pytest

from gateware.dlpc410 import prng_model, schedule
from gateware.dlpc410.facts import DMDS, TEST_DMD
from gateware.dlpc410.params import DURATION_BITS, LSB_BITS, PlaneOrder, Registers, ResetMode, Source
from sim.tb.plane_source import ramp_image

XGA = DMDS["dlp7000"]


def test_bound_matches_derived_figure():
    # DLPC410.md "Derived bounds": about 312 Hz at 200 MHz for 8-bit continuous-light PWM
    assert 305 < schedule.bound(XGA, 200e6) < 315
    assert schedule.bound(XGA, 200e6, depth=1) > 50 * schedule.bound(XGA, 200e6)


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


def test_binary_rates_match_ti_table():
    """Phased binary patterns at 400 MHz reach TI's 32,552 Hz (loose RST reading); global ones
    the table's neighbourhood of 22,614 Hz."""
    phased = schedule.plan(XGA, 400e6, depth=1, chain=True, reset_mode=ResetMode.SINGLE, strict_rst=False)
    assert round(phased.rate_hz) == 32552 and phased.binds.startswith("bus")
    glob = schedule.plan(XGA, 400e6, depth=1, chain=True)
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
    w = prng_model.words(1, 3)
    assert w[0] == 0x40822041 and len(set(w)) == 3
    assert prng_model.words(0, 1) == prng_model.words(prng_model.ZERO_SEED, 1)
    bits = np.unpackbits(np.array(prng_model.words(7, 4096), dtype="<u8").view(np.uint8))
    assert abs(bits.mean() - 0.5) < 0.01


def test_prng_patterns_follow_commands():
    p = schedule.plan(TEST_DMD, 200e6, depth=1, chain=True, source=Source.PRNG,
                      t_rst_s=100e-9, t_settle_s=150e-9).params
    start = schedule.ready_cycle(TEST_DMD, p, schedule.Frame(0, 1))
    r = schedule.simulate(TEST_DMD, p, [], [start], max_frames=3)
    shown = prng_model.shown_patterns(TEST_DMD, r.commands, 5)
    assert len(shown) >= 3 and not np.array_equal(shown[0], shown[1])


@pytest.mark.parametrize("dmd", [TEST_DMD, XGA, DMDS["dlp9500"]])
def test_pulse_encodings_decode_to_their_groups(dmd):
    """The model's block commands and the decoder's reading of them agree for every group."""
    from sim.models.dlpc410_commands import pulse_blocks
    for mode in ResetMode:
        for g, blocks in enumerate(schedule.groups(dmd, mode)):
            assert pulse_blocks(dmd, *schedule.pulse_encoding(dmd, mode, g)) == tuple(blocks)


def test_decoder_rejects_a_broken_row_cycle():
    from sim.models.dlpc410_commands import CommandDecoder
    lanes = {(b, e): 0 for b in "AB" for e in ("rise", "fall")}
    dec = CommandDecoder(XGA)
    dec.step(0, 1, 0b10, 5, 0, 0, 1, lanes)
    with pytest.raises(AssertionError):
        dec.step(1, 0, 0, 0, 0, 0, 1, lanes)


@pytest.mark.parametrize("chain", [False, True])
def test_newer_frame_taken_while_waiting_only_when_triggered(chain):
    """Triggered: a frame offered while every group waits loaded is taken at once and its first
    plane loaded again (a trigger meanwhile is an overrun). Chained: frames are taken only at
    frame ends, as before."""
    p = schedule.plan(TEST_DMD, 200e6, depth=1, chain=chain, t_rst_s=20 / 200e6, t_settle_s=30 / 200e6).params
    start = schedule.ready_cycle(TEST_DMD, p, schedule.Frame(0, 1))
    offered = start + 100
    r = schedule.simulate(TEST_DMD, p, [schedule.Frame(0, 1), schedule.Frame(1, 1, ready=offered)],
                          [offered + 2], until=offered + 400)
    if chain:
        assert r.overruns == 0 and r.accepted == [offered + 2]
        assert [f.slot for f in r.shown] == [0, 1]      # taken at the end of a chained frame
        assert r.pulses[0][3] == 0
    else:
        assert r.overruns == 1 and not r.accepted and [f.slot for f in r.shown] == [0, 1]
        rows = [t for t, k, _a in r.commands if k == "row" and t > offered]
        assert len(rows) == TEST_DMD.rows and rows[0] == offered + schedule.RELOAD_LEAD
