"""The sync master against a plain model: random triggers (pin and software) and ready lines;
every obeyed trigger gives one pulse of ``width`` cycles on every output at once and on the
camera output; every refused one is counted under its cause."""

import random

from amaranth.sim import Simulator

from gateware.registers import TriggerMode
from gateware.sync.master import SyncMaster
from sim.models.sync_master_model import SyncMasterModel, scenario

BOARDS = 4
SYNC_STAGES = 2      # the trigger pin's and the ready lines' synchronisers


def test_pulses_and_refusals():
    dut = SyncMaster(BOARDS)
    width, min_period, cycles = 3, 40, 3100
    triggers, ready_at = scenario(random.Random(3), BOARDS, cycles)
    model = SyncMasterModel(BOARDS, min_period=min_period, stages=SYNC_STAGES)
    seen_pulses, obeyed = [], []

    async def bench(ctx):
        ctx.set(dut.mode, TriggerMode.SOFTWARE)
        ctx.set(dut.width, width)
        ctx.set(dut.min_period, min_period)
        ctx.set(dut.run, 1)
        prev_out = 0
        for t in range(cycles):
            ctx.set(dut.ready, ready_at(t))
            ctx.set(dut.soft, t in triggers)
            await ctx.tick()
            if model.cycle(t, ready_at(t), t in triggers):
                obeyed.append(t)
            out = ctx.get(dut.sync_out)
            assert out in (0, (1 << BOARDS) - 1), "every board's pulse on the same cycles"
            assert bool(out) == bool(ctx.get(dut.camera_out))
            if out and not prev_out:
                seen_pulses.append(t)
            prev_out = out
        for name, count in model.counts.items():
            assert ctx.get(getattr(dut, name)) == count, name
        counts = model.counts
        # the decision is registered into the pads: each pulse leaves the cycle after its trigger
        assert seen_pulses == [t + 1 for t in obeyed]
        assert counts["pulses"] > 10 and counts["not_ready"] > 0 and counts["early"] > 0

    sim = Simulator(dut)
    sim.add_clock(5e-9)
    sim.add_testbench(bench)
    sim.run()


def test_pulse_width():
    dut = SyncMaster(2)

    async def bench(ctx):
        ctx.set(dut.mode, TriggerMode.SOFTWARE)
        ctx.set(dut.width, 5)
        ctx.set(dut.run, 1)
        ctx.set(dut.ready, 0b11)
        await ctx.tick().repeat(4)
        ctx.set(dut.soft, 1)
        await ctx.tick()
        ctx.set(dut.soft, 0)
        high = 0
        for _ in range(20):
            await ctx.tick()
            high += bool(ctx.get(dut.sync_out))
        assert high == 5

    sim = Simulator(dut)
    sim.add_clock(5e-9)
    sim.add_testbench(bench)
    sim.run()
