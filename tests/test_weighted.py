"""Two DMDs in weighted light (:mod:`host.weighted`): the split against a numpy oracle, the trim
against a model of the light, and two boards of the tiled rig's generated Verilog showing a ramp
of 8-bit levels as 4 + 4 bits under the camera model (:mod:`sim.models.weighted_light_model`)."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from host import weighted
from host.cli import main
from sim.models import weighted_light_model as light
from sim.rigs.tiled_rig import Oscillator, master_period, run_tiled
from spec.facts import TEST_DMD
from spec.registers import TriggerMode

SPLITS = [(n, k) for n in (8, 12, 16) for k in range(max(1, n - 8), min(8, n - 1) + 1)]


@settings(max_examples=4, deadline=None)
@given(st.sampled_from(SPLITS), st.integers(0, 2**32 - 1))
def test_split_and_recombine(split, seed):
    bits, low_bits = split
    rng = np.random.default_rng(seed)
    image = rng.integers(0, 1 << bits, (6, 7), dtype=np.uint16)
    image.flat[:2] = (0, (1 << bits) - 1)
    high, low = weighted.split(image, bits, low_bits)
    depth = weighted.depth_of(bits, low_bits)
    assert depth == max(low_bits, bits - low_bits) <= 8
    # oracle: the high part's levels weigh 2**k each, the low part's 1
    assert high.max() < 2 ** (bits - low_bits) and low.max() < 2 ** low_bits
    assert np.array_equal(high.astype(np.int64) * 2 ** low_bits + low, image)
    assert np.array_equal(weighted.combine(high, low, low_bits), image)
    # each board's bytes carry its level in their top ``depth`` bits
    for part in (high, low):
        sent = weighted.board_bytes(part, depth)
        assert sent.dtype == np.uint8 and np.array_equal(sent >> (8 - depth), part)


def test_split_refuses_what_two_boards_cannot_show():
    with pytest.raises(ValueError):
        weighted.split(np.array([[256]], np.uint16), 8)
    with pytest.raises(ValueError):
        weighted.depth_of(16, 7)                 # board A would need 9 bits
    with pytest.raises(ValueError):
        weighted.depth_of(17, 8)
    assert list(weighted.low_bits_range(12)) == [4, 5, 6, 7, 8]


class Lamps:
    """Model of the light (written for the test): board x sends intensity * lsb * level cycles of
    light; board B's intensity is 2**-k (1 + error) of A's."""

    def __init__(self, low_bits, error):
        self.k, self.error = low_bits, error

    def reading(self, board, level, lsb):
        intensity = 1.0 if board == "a" else 2.0 ** -self.k * (1 + self.error)
        return intensity * lsb * level

    def grey(self, high, low, lsb_a, lsb_b, lsb):
        """n-bit LSB at the plan's ``lsb``."""
        return (self.reading("a", high, lsb_a) + self.reading("b", low, lsb_b)) * 2.0 ** self.k / lsb


@pytest.mark.parametrize("bits,error", [(8, -0.03), (12, -0.03), (12, 0.03), (16, 0.05), (16, -0.2)])
def test_trim_makes_the_ratio_exact(bits, error):
    dual = weighted.plan(TEST_DMD, 200e6, bits, t_rst_s=20 / 200e6, t_settle_s=30 / 200e6)
    k, lsb = dual.low_bits, dual.lsb
    lamps = Lamps(k, error)
    full_a, full_b = 2 ** dual.high_bits - 1, 2 ** k - 1
    measured = weighted.measure(lamps.reading("a", full_a, lsb) + 5, lamps.reading("b", full_b, lsb) + 5,
                                level_a=full_a, level_b=full_b, low_bits=k, lsb_a=lsb, lsb_b=lsb, dark=5)
    assert measured == pytest.approx(error, rel=1e-9)
    trimmed = weighted.trim(dual, measured, TEST_DMD)
    assert trimmed.lsb_a % 2 == 0 == trimmed.lsb_b % 2
    assert min(trimmed.lsb_a, trimmed.lsb_b) == lsb           # the bright board keeps the plan's
    assert max(trimmed.lsb_a, trimmed.lsb_b) > lsb
    assert (trimmed.lsb_b > lsb) == (error < 0)
    # untrimmed the largest low level is off by error * (2**k - 1); trimmed by under a cycle's worth
    top = lamps.grey(0, full_b, lsb, lsb, lsb) - full_b
    assert top == pytest.approx(error * full_b)
    levels = np.arange(2 ** bits)
    high, low = levels >> k, levels & (2 ** k - 1)
    shown = lamps.grey(high, low, trimmed.lsb_a, trimmed.lsb_b, lsb) * lsb / trimmed.lsb_a
    assert np.abs(shown - levels).max() <= full_b * 1.0 / lsb + 1e-9
    assert abs(trimmed.residual) <= 1.0 / lsb
    # the entries: 0 (the register's) on the bright board
    assert trimmed.entry_lsb("a" if error < 0 else "b", lsb) == 0
    # the lengthened board's frame is the longer
    assert weighted.trimmed_frame_cycles(dual, trimmed, TEST_DMD) > dual.plan.frame_cycles


#: Two pairs of boards (the tiled rig's four-board build, shared with tests/test_tiled_verilog.py):
#: boards 0 and 1 exact, boards 2 and 3 with B 3 % dim and trimmed by its entries' lsb.
OSCILLATORS = [Oscillator(30), Oscillator(-30, jitter_ps=20, seed=3), Oscillator(10, seed=5),
               Oscillator(-10, jitter_ps=20, seed=7)]
FRAMES = 5
ERROR = -0.03


@pytest.mark.verilog
def test_two_boards_show_every_8_bit_level():
    dmd = TEST_DMD
    dual = weighted.plan(dmd, 200e6, 8, t_rst_s=20 / 200e6, t_settle_s=30 / 200e6)
    k, depth, lsb = dual.low_bits, dual.depth, dual.lsb
    trimmed = weighted.trim(dual, ERROR, dmd)
    rows, columns = np.indices((dmd.rows, dmd.columns))
    ramp = ((columns + 128 * (rows % 2)) & 255).astype(np.uint16)
    scenes = {0: ramp, 1: 255 - ramp}                          # two distinct frames, in turn
    parts = {s: dual.images(image) for s, image in scenes.items()}
    slots = [f % 2 for f in range(FRAMES)]
    images, offered = [], []
    for pair in range(2):
        for board in ("a", "b"):
            images.append({s: parts[s][board] for s in scenes})
            entry_lsb = trimmed.entry_lsb(board, lsb) if pair else 0
            offered.append([(s, depth, 0, 1, {"lsb": entry_lsb}) for s in slots])
    frame = weighted.trimmed_frame_cycles(dual, trimmed, dmd)
    run = run_tiled(dmd, dual.params(), images, oscillators=OSCILLATORS, frames=FRAMES, depth=depth,
                    master_period_cycles=master_period(frame), name="two_boards_weighted", offered=offered)
    assert run.counts == {"pulses": FRAMES, "not_ready": 0, "early": 0}
    for i, status in enumerate(run.status):
        assert status["frames"] == FRAMES and status["late"] == status["overruns"] == 0, (i, status)
    boards = [run.board_run(i, dmd) for i in range(4)]          # the rule model on every board's pins
    for board in boards:
        assert [slot for _now, slot in board.releases][:FRAMES - 1] == slots[:FRAMES - 1]
    for pair, ratio_error in ((0, 0.0), (1, ERROR)):
        a, b = 2 * pair, 2 * pair + 1
        for frame_k in range(1, FRAMES - 1):
            window = run.syncs[frame_k], run.syncs[frame_k + 1]
            low_light = run.light(b, boards[b], *window, lsb)
            seen = light.grey(run.light(a, boards[a], *window, lsb), low_light, k, ratio_error)
            error = seen - scenes[slots[frame_k]]
            # board B's planes as long as its entries say: the trimmed pair's 3 % longer
            low = scenes[slots[frame_k]] & (2 ** k - 1)
            stretch = (trimmed.lsb_b if pair else lsb) / lsb
            assert np.abs(low_light - low * stretch).max() < 0.01, (pair, frame_k)
            assert np.abs(error).max() < 0.5, (pair, frame_k, np.abs(error).max())
    # the pair in lockstep: each plane's pulse on B within the boards' sampling of the sync pulse
    # (two cycles) and their clocks' drift over the frame of A's
    errors = light.sync_errors_ns(run.pulses[0][0], run.pulses[1][0], run.syncs)
    assert len(errors) >= FRAMES - 1
    assert max(np.abs(e).max() for e in errors) <= 2 * 5 + 60e-6 * frame * 5 + 0.1


def test_cli_dual_sends_each_board_its_part(tmp_path, capsys):
    """``python -m host dual``: board A gets the high bits, B the low bits (the trim lengthening
    the dim board's planes), both in SYNC mode at the dual depth."""
    from test_host_client import FakeProjector
    rng = np.random.default_rng(3)
    image = rng.integers(0, 1 << 12, (TEST_DMD.rows, TEST_DMD.columns), dtype=np.uint16)
    np.save(path := tmp_path / "scene.npy", image)
    boards = [FakeProjector().start() for _ in range(2)]
    try:
        args = ["--timeout", "2", "dual", *[f"127.0.0.1:{b.port}" for b in boards], str(path), "--bits", "12",
                "--dmd", "test", "--dclk", "200e6", "--ratio-error", "-0.03"]
        assert main(args) == 0, capsys.readouterr().err
        out = capsys.readouterr().out
        assert "12-bit as 6 + 6 bits" in out and "board B at 127.0.0.1" in out
        dual = weighted.plan(TEST_DMD, 200e6, 12)
        (regs_a,), (regs_b,) = boards[0].model.registers, boards[1].model.registers
        assert regs_a["trigger"] == regs_b["trigger"] == TriggerMode.SYNC
        assert regs_a["lsb"] == dual.lsb < regs_b["lsb"] == weighted.trim(dual, -0.03).lsb_b
        for board, want in zip(boards, weighted.split(image, 12), strict=True):
            assert board.depths == [6]
            frame = max(board.stored)[0]
            assert np.array_equal(board.image(frame) >> 2, want)
    finally:
        for b in boards:
            b.close()
