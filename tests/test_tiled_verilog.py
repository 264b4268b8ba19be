"""The tiled display on the generated Verilog: a sync master and four boards, each on its own
crystal (+-100 ppm, one drifting, two jittering), in one Verilator simulation
(:mod:`sim.rigs.tiled_rig`, testbench :mod:`sim.tb.tiled_rig_tb`).

Every board must obey every pulse and play its tile exactly under the rule model, and the
spread of the boards' clocking pulses must stay inside what the clocks explain: the board's
sampling of the pulse (its bus decides on even cycles only: two cycles), plus the frequency
difference over the time since the pulse, plus the jitter. The oscillators' rates are checked
from the recorded times, so that the spread is measured on the clocks the test claims.
"""

import numpy as np
import pytest

from sim.models.camera_model import to_lsb
from sim.rigs.tiled_rig import BOARD_PERIOD_FS, Oscillator, master_period, run_tiled, tiles
from sim.tb.seq_sim import frame_lights
from spec import schedule
from spec.facts import TEST_DMD

FRAMES = 6
OSCILLATORS = [Oscillator(100), Oscillator(-100, jitter_ps=20, seed=3), Oscillator(37, ramp_ppm_per_s=5000, seed=5),
               Oscillator(-61, jitter_ps=50, seed=7)]
MASTER = Oscillator(-20, seed=11)


@pytest.mark.verilog
def test_tiled_boards_follow_the_master():
    dmd = TEST_DMD
    plan = schedule.plan(dmd, 200e6, depth=8, t_rst_s=20 / 200e6, t_settle_s=30 / 200e6)
    p = plan.params
    images = tiles(dmd, len(OSCILLATORS))
    run = run_tiled(dmd, p, images, oscillators=OSCILLATORS, master=MASTER, frames=FRAMES,
                    master_period_cycles=master_period(plan.frame_cycles), name="tiled_boards_follow_the_master")

    assert run.counts == {"pulses": FRAMES, "not_ready": 0, "early": 0}
    assert len(run.syncs) == FRAMES
    for i, status in enumerate(run.status):
        assert status["frames"] == FRAMES and status["triggers"] == FRAMES, (i, status)
        assert status["overruns"] == status["late"] == status["underruns"] == 0, (i, status)

    # each board's pins under the rule model; every frame shows its tile exactly, in its cycles
    boards = [run.board_run(i, dmd) for i in range(len(images))]
    for i, (board, image) in enumerate(zip(boards, images, strict=True)):
        windows = board.frames()
        assert len(windows) == FRAMES, (i, windows)
        for light in frame_lights(board.model, windows):
            error = to_lsb(light, p.lsb) - image
            assert np.abs(error).max() == 0, f"board {i}: {np.abs(error).max()} LSB"

    # one camera over the whole scene, from one sync pulse to the next, in real time: each tile
    # is off by its clock's error only (a fast board's planes are short), seams included
    for k in range(1, FRAMES - 1):
        seen = [run.light(i, board, run.syncs[k], run.syncs[k + 1], p.lsb) for i, board in enumerate(boards)]
        for i, (tile, image, osc) in enumerate(zip(seen, images, OSCILLATORS, strict=True)):
            expect = image * (1 - osc.error(run.syncs[k] / 1e12))
            assert np.abs(tile - expect).max() < 2e-3, (k, i, np.abs(tile - expect).max())

    # the oscillators run at the rates asked: from the pulses' times and cycles
    for i, (osc, (times, _cycles, _values)) in enumerate(zip(OSCILLATORS, run.pulses, strict=True)):
        middle_s = (times[0] + times[-1]) / 2e12
        measured_ppm = run.rate_ppm(i)
        assert abs(measured_ppm - osc.error(middle_s) * 1e6) < 0.5, (i, measured_ppm)

    # the spread of every pulse of every frame, against what the clocks explain
    spreads = run.spreads()
    assert spreads.shape[0] == FRAMES
    per_board = run.frame_pulses()
    jitter_ns = 2 * max(o.jitter_ps for o in OSCILLATORS) / 1000
    for k in range(FRAMES):
        since_ns = (per_board[0][k] - run.syncs[k]) / 1000
        errors = [o.error(run.syncs[k] / 1e12) for o in OSCILLATORS]
        bound = 2 * BOARD_PERIOD_FS / 1e6 * 1.0002 + (max(errors) - min(errors)) * since_ns + jitter_ns + 0.01
        assert np.all(spreads[k] <= bound), (k, spreads[k], bound)
    # the drift is there to see: the last pulse spreads wider than the first, on average
    assert spreads[:, -1].mean() > spreads[:, 0].mean() + 5


@pytest.mark.verilog
def test_tiled_boards_lock_their_clocks_to_the_master():
    """Each board's clock loop on (:class:`gateware.sync.clock_trim.ClockTrim`, its VCXO
    modelled by the oscillator's trim input): every loop locks to the master's rate, and then
    every board takes each pulse on the same edge of its own clock, so the spread is a fraction
    of a cycle, not the two cycles of sampling and the drift a frame as without."""
    dmd, frames = TEST_DMD, 150
    plan = schedule.plan(dmd, 200e6, depth=4, t_rst_s=20 / 200e6, t_settle_s=30 / 200e6)
    images = tiles(dmd, len(OSCILLATORS))
    run = run_tiled(dmd, plan.params, images, oscillators=OSCILLATORS, master=MASTER, frames=frames, depth=4,
                    master_period_cycles=master_period(plan.frame_cycles), name="tiled_boards_lock_their_clocks",
                    trim=True)
    assert run.counts == {"pulses": frames, "not_ready": 0, "early": 0}
    for i, (status, loop) in enumerate(zip(run.status, run.loops, strict=True)):
        assert status["frames"] == frames and status["overruns"] == status["late"] == 0, (i, status)
        assert loop["locked"] and loop["slips"] == 0 and loop["pulses"] == frames, (i, loop)
    # every board now runs at the master's rate (its crystal -20 ppm): from the last 50 frames
    for i in range(len(run.pulses)):
        measured_ppm = run.rate_ppm(i, run.syncs[-50])
        assert abs(measured_ppm - MASTER.ppm) < 5, (i, measured_ppm)
    for i, image in enumerate(images):
        board = run.board_run(i, dmd)
        lights = frame_lights(board.model, board.frames())
        assert len(lights) == frames
        assert all(np.array_equal(to_lsb(light, plan.params.lsb), image >> 4) for light in lights), i
    spreads = run.spreads()
    assert spreads[:20].max() > 5, "before the lock the boards sample the pulse cycles apart"
    assert spreads[-50:].max() < 2, spreads[-50:].max()
