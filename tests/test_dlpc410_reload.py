"""The sequencer takes new registers while it rests (:attr:`Sequencer.at_rest`) and, told to
``reload``, loads its waiting frame's first plane again under them: the next trigger shows the
frame exactly as the new registers say, under the rule-checking DLPC410 model (on the generated
Verilog, :mod:`sim.rigs.seq_rig`, testbench :mod:`sim.tb.seq_rig_tb`, TEST_DMD)."""

import numpy as np
import pytest

from gateware.registers import Registers
from sim.harness.layout import pack
from sim.models.camera_model import Camera, to_lsb
from sim.rigs.seq_rig import run_script
from sim.tb.plane_source import ramp_image
from spec import schedule
from spec.facts import TEST_DMD
from spec.registers import PlaneOrder, ResetMode

DMD = TEST_DMD
FAST = {"t_rst_s": 20 / 200e6, "t_settle_s": 30 / 200e6}
#: The Amaranth testbenches these replace failed after 1 ms of simulated time.
DEADLINE_CYCLES = 200_000


def regs(values):
    return {"op": "set", "signal": "regs", "value": pack(Registers, values)}


def until(level):
    """``await ctx.tick().until(at_rest == level)``"""
    return {"op": "until", "signal": "at_rest", "level": level}


TRIGGER = [{"op": "set", "signal": "trigger_in", "value": 1}, {"op": "ticks", "count": 4},
           {"op": "set", "signal": "trigger_in", "value": 0}]


@pytest.mark.verilog
def test_new_registers_at_rest_reload_the_waiting_frame(test_name):
    before = schedule.plan(DMD, 200e6, **FAST)
    # another grouping of the blocks, the other plane order, planes twice as long: the plane
    # loaded under the old registers (the most significant, all blocks) is the wrong one now
    after = schedule.plan(DMD, 200e6, **FAST, reset_mode=ResetMode.DUAL, order=PlaneOrder.LSB_FIRST,
                          exposure_s=2 * before.params.lsb / 200e6)
    script = [
        until(0),                                     # the frame is taken, its first plane loads
        until(1),                                     # loaded, waiting for a trigger
        {"op": "set", "signal": "reload", "value": 1},   # as the register crossing does it: reload
        {"op": "ticks", "count": 1},                  # in the cycle the registers change
        {"op": "set", "signal": "reload", "value": 0},
        regs(after.params.registers(DMD)),
        {"op": "observe", "name": "rest_after_reload", "signals": ["at_rest"]},
        until(1),                                     # loaded again under the new registers
        *TRIGGER,
        {"op": "ticks", "count": after.frame_cycles + 200},
        {"op": "observe", "name": "end", "signals": ["status"]},
    ]
    run = run_script(DMD, before.params, [(0, 8)], script=script, name=test_name, max_cycles=DEADLINE_CYCLES)
    model, seen = run.model, run.report["observed"]
    assert not seen["rest_after_reload"]["at_rest"], "the sequencer rested while loading again"
    assert {k: seen["end"]["status"][k] for k in ("triggers", "overruns", "late")} == \
        {"triggers": 1, "overruns": 0, "late": 0}
    pulses = [c.cycle for c in model.log if c.kind == "pulse"]
    light = Camera(model, ramp_cycles=0, visible=False).image(pulses[0], pulses[0] + after.frame_cycles)
    assert np.array_equal(to_lsb(light, after.params.lsb), ramp_image(DMD, 0))


@pytest.mark.verilog
def test_chained_run_ends_at_a_frame_end_when_chain_drops(test_name):
    """A chained run never rests; the system top clears ``chain`` while disarmed. The frame that
    is playing then ends as a triggered frame does (dark pulse, sync out low), the sequencer
    rests, and no pulse follows: every rule of the DLPC410 kept, no pulse late."""
    plan = schedule.plan(DMD, 200e6, **FAST, chain=True)
    values = plan.params.registers(DMD)
    script = [
        until(0),
        until(1),
        *TRIGGER,
        {"op": "ticks", "count": plan.frame_cycles * 5 // 2},    # two and a half chained frames
        {"op": "observe", "name": "before", "signals": ["at_rest", "status"]},
        regs({**values, "chain": 0}),
        {"op": "wait_for", "signal": "at_rest", "level": 1, "name": "to_rest"},
        {"op": "observe", "name": "at_rest", "signals": ["sync_out", "status"]},
        {"op": "ticks", "count": plan.frame_cycles},
        {"op": "observe", "name": "end", "signals": ["status"]},
    ]
    run = run_script(DMD, plan.params, [(0, 8)], script=script, name=test_name, max_cycles=DEADLINE_CYCLES)
    seen = run.report["observed"]
    assert not seen["before"]["at_rest"]
    assert seen["before"]["status"]["frames"] == 3
    assert seen["to_rest"] <= plan.frame_cycles, "the playing frame did not end the run"
    assert not seen["at_rest"]["sync_out"]
    assert {k: seen["end"]["status"][k] for k in ("frames", "triggers", "overruns", "late")} == \
        {"frames": 3, "triggers": 1, "overruns": 0, "late": 0}
    # the model's cycle of the first cycle at rest: no pulse from there on
    rest = seen["at_rest"]["status"]["now"] - run.shift
    assert [c.cycle for c in run.model.log if c.kind == "pulse" and c.cycle >= rest] == [], "a pulse at rest"
