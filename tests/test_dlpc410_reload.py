"""The sequencer takes new registers while it rests (:attr:`Sequencer.at_rest`) and, told to
``reload``, loads its waiting frame's first plane again under them: the next trigger shows the
frame exactly as the new registers say, under the rule-checking DLPC410 model (Amaranth sim,
TEST_DMD)."""

import numpy as np

from gateware.registers import Registers
from sim.harness.amaranth_sim import simulate
from sim.models.camera import Camera, to_lsb
from sim.models.dlpc410 import amaranth_process
from sim.tb.plane_source import SequencerBench, ramp_image
from sim.tb.seq_sim import dlpc410_for
from spec import schedule
from spec.facts import TEST_DMD
from spec.registers import PlaneOrder, ResetMode

DMD = TEST_DMD
FAST = {"t_rst_s": 20 / 200e6, "t_settle_s": 30 / 200e6}


def test_new_registers_at_rest_reload_the_waiting_frame(test_name):
    before = schedule.plan(DMD, 200e6, **FAST)
    # another grouping of the blocks, the other plane order, planes twice as long: the plane
    # loaded under the old registers (the most significant, all blocks) is the wrong one now
    after = schedule.plan(DMD, 200e6, **FAST, reset_mode=ResetMode.DUAL, order=PlaneOrder.LSB_FIRST,
                          exposure_s=2 * before.params.lsb / 200e6)
    dut = SequencerBench(DMD, [(0, 8)])
    model = dlpc410_for(DMD, before.params)
    seen = {}

    async def bench(ctx):
        ctx.set(dut.regs, Registers.const(before.params.registers(DMD)))
        ctx.set(dut.release.ready, 1)
        await ctx.tick().until(~dut.at_rest)          # the frame is taken, its first plane loads
        await ctx.tick().until(dut.at_rest)           # loaded, waiting for a trigger
        ctx.set(dut.reload, 1)                        # as the register crossing does it: reload
        await ctx.tick()                              # in the cycle the registers change
        ctx.set(dut.reload, 0)
        ctx.set(dut.regs, Registers.const(after.params.registers(DMD)))
        seen["rest_after_reload"] = ctx.get(dut.at_rest)
        await ctx.tick().until(dut.at_rest)           # loaded again under the new registers
        ctx.set(dut.trigger_in, 1)
        await ctx.tick().repeat(4)
        ctx.set(dut.trigger_in, 0)
        await ctx.tick().repeat(after.frame_cycles + 200)
        seen["status"] = {k: int(getattr(ctx.get(dut.status), k)) for k in ("triggers", "overruns", "late")}

    simulate(dut, [bench], name=test_name, clocks={"sync": 200e6}, processes=[amaranth_process(model, dut.pins)],
             deadline=1e-3)
    assert not seen["rest_after_reload"], "the sequencer rested while loading again"
    assert seen["status"] == {"triggers": 1, "overruns": 0, "late": 0}
    pulses = [c.cycle for c in model.log if c.kind == "pulse"]
    light = Camera(model, ramp_cycles=0, visible=False).image(pulses[0], pulses[0] + after.frame_cycles)
    assert np.array_equal(to_lsb(light, after.params.lsb), ramp_image(DMD, 0))


def test_chained_run_ends_at_a_frame_end_when_chain_drops(test_name):
    """A chained run never rests; the system top clears ``chain`` while disarmed. The frame that
    is playing then ends as a triggered frame does (dark pulse, sync out low), the sequencer
    rests, and no pulse follows: every rule of the DLPC410 kept, no pulse late."""
    plan = schedule.plan(DMD, 200e6, **FAST, chain=True)
    regs = plan.params.registers(DMD)
    dut = SequencerBench(DMD, [(0, 8)])
    model = dlpc410_for(DMD, plan.params)
    seen = {}

    async def bench(ctx):
        ctx.set(dut.regs, Registers.const(regs))
        ctx.set(dut.release.ready, 1)
        await ctx.tick().until(~dut.at_rest)
        await ctx.tick().until(dut.at_rest)
        ctx.set(dut.trigger_in, 1)
        await ctx.tick().repeat(4)
        ctx.set(dut.trigger_in, 0)
        await ctx.tick().repeat(plan.frame_cycles * 5 // 2)    # two and a half chained frames
        assert not ctx.get(dut.at_rest)
        seen["frames_before"] = ctx.get(dut.status.frames)
        ctx.set(dut.regs, Registers.const({**regs, "chain": 0}))
        cycles = 0
        while not ctx.get(dut.at_rest):
            await ctx.tick()
            cycles += 1
        seen["to_rest"] = cycles
        seen["sync_out"] = ctx.get(dut.sync_out)
        seen["pulses_at_rest"] = sum(1 for c in model.log if c.kind == "pulse")
        await ctx.tick().repeat(plan.frame_cycles)
        st = ctx.get(dut.status)
        seen["status"] = {k: int(getattr(st, k)) for k in ("frames", "triggers", "overruns", "late")}

    simulate(dut, [bench], name=test_name, clocks={"sync": 200e6}, processes=[amaranth_process(model, dut.pins)],
             deadline=1e-3)
    assert seen["frames_before"] == 3
    assert seen["to_rest"] <= plan.frame_cycles, "the playing frame did not end the run"
    assert not seen["sync_out"]
    assert seen["status"] == {"frames": 3, "triggers": 1, "overruns": 0, "late": 0}
    assert sum(1 for c in model.log if c.kind == "pulse") == seen["pulses_at_rest"], "a pulse at rest"
