"""The sequencer's generated Verilog on full XGA, on the full DLP9500 (1080p, four buses) at DCLK
400 MHz with rows at the row cycle, and on the small four-bus geometries (one under the four-DMD
paper's settle reading), on the sequencer rig (:mod:`sim.rigs.seq_rig`, testbench
:mod:`sim.tb.seq_rig_tb`): one triggered frame of the ramp image (every grey level on every row),
RST_ACTIVE and settle scaled down (run-time parameters). The rule-checking DLPC410 model, on the
replayed pin trace, must break no rule and agree with the responder; its command log must equal the
schedule model's cycle for cycle, and the camera model must see every pixel integrate exactly its
grey level."""

import numpy as np
import pytest

from gateware.dlpc410.trigger import PIN_TO_STROBE
from sim.rigs.seq_rig import run_rig
from sim.tb.plane_source import ramp_image
from sim.tb.seq_sim import frame_lights
from spec import schedule
from spec.facts import DMDS
from spec.registers import PlaneOrder, ResetMode


@pytest.mark.verilog
@pytest.mark.parametrize("dmd,mode,strict,order,depth,dclk,words,reading", [
    ("dlp7000", "GLOBAL", True, "MSB_FIRST", 8, 200e6, 1, "ti"),     # every grey level 0..255
    ("dlp7000", "SINGLE", False, "LSB_FIRST", 4, 200e6, 1, "ti"),    # phased: 16 groups; 4 bits keep it short
    ("test4", "QUAD", True, "MSB_FIRST", 8, 200e6, 1, "ti"),         # four buses (DIN_A..D), 1080p-style clears
    # full 1080p, four buses, two beats a cycle, rows at the row cycle (four store words a cycle)
    ("dlp9500", "GLOBAL", True, "MSB_FIRST", 8, 400e6, 4, "ti"),
    # the four-DMD paper's settle reading: loads while the mirrors settle, pulses a settle apart
    ("test4_400", "GLOBAL", True, "MSB_FIRST", 8, 400e6, 2, "paper"),
])
def test_sequencer_verilog_xga(dmd, mode, strict, order, depth, dclk, words, reading, test_name):
    dmd = DMDS[dmd]
    p = schedule.plan(dmd, dclk, t_rst_s=40 / 200e6, t_settle_s=80 / 200e6, reset_mode=ResetMode[mode],
                      strict_rst=strict, order=PlaneOrder[order], depth=depth, words_per_cycle=words,
                      reading=reading).params
    assert p.t_flip == (80 if reading == "paper" else 0) and p.lsb >= p.t_flip
    frames = [schedule.Frame(0, depth)]   # repeated: a newer frame offered while waiting would be reloaded
    pin = max(g.loaded_at for g in schedule.simulate(dmd, p, frames).groups) + 6
    model_run = schedule.simulate(dmd, p, frames, [pin + PIN_TO_STROBE])
    end = model_run.commands[-1][0] + 64
    run = run_rig(dmd, p, [(0, depth)], pins=[pin], cycles=end, name=test_name, store_words=words)
    assert run.model.reading.name == reading
    got = [c for c in run.commands if c[0] < end]
    want = [c for c in model_run.decoded() if c[0] < end]
    first = next((i for i, (x, y) in enumerate(zip(got, want, strict=False)) if x != y), None)
    where = None if first is None else (got[first], want[first])
    assert got == want, f"{len(got)} vs {len(want)} commands; first difference at {first}: {where}"
    windows = run.frames()
    assert len(windows) == 1, f"one frame expected: {windows}"
    (light,) = frame_lights(run.model, windows)
    expect = (ramp_image(dmd, 0).astype(np.int64) >> (8 - depth)) * p.lsb
    assert np.array_equal(light, expect), f"max error {np.abs(light - expect).max() / p.lsb} LSB"
