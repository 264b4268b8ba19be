"""The sync master against a plain model: random triggers (pin and software) and ready lines;
every obeyed trigger gives one pulse of ``width`` cycles on every output at once and on the
camera output; every refused one is counted under its cause."""

import random

from amaranth.sim import Simulator

from gateware.registers import TriggerMode
from gateware.sync.master import SyncMaster

BOARDS = 4
SYNC_STAGES = 2      # the trigger pin's and the ready lines' synchronisers


def test_pulses_and_refusals():
    dut = SyncMaster(BOARDS)
    rng = random.Random(3)
    width, min_period = 3, 40
    soft_at = sorted(rng.sample(range(50, 3000), 60))
    # a board not ready for a while, now and then
    windows = [(start, start + rng.randrange(30, 120), rng.randrange(BOARDS))
               for start in sorted(rng.sample(range(0, 3000), 12))]
    expect = {"pulses": 0, "not_ready": 0, "early": 0}
    seen_pulses = []

    async def bench(ctx):
        ctx.set(dut.mode, TriggerMode.SOFTWARE)
        ctx.set(dut.width, width)
        ctx.set(dut.min_period, min_period)
        ctx.set(dut.run, 1)
        history = [(1 << BOARDS) - 1] * 8          # ready lines as the master saw them, by cycle
        last_pulse = None
        prev_out = 0
        for t in range(3100):
            ready = (1 << BOARDS) - 1
            for start, end, board in windows:
                if start <= t < end:
                    ready &= ~(1 << board)
            ctx.set(dut.ready, ready)
            ctx.set(dut.soft, t in soft_at)
            await ctx.tick()
            history.append(ready)
            if t in soft_at:
                synced = history[-1 - SYNC_STAGES]
                if last_pulse is not None and t - last_pulse < min_period:
                    expect["early"] += 1
                elif synced != (1 << BOARDS) - 1:
                    expect["not_ready"] += 1
                else:
                    expect["pulses"] += 1
                    last_pulse = t
            out = ctx.get(dut.sync_out)
            assert out in (0, (1 << BOARDS) - 1), "every board's pulse on the same cycles"
            assert bool(out) == bool(ctx.get(dut.camera_out))
            if out and not prev_out:
                seen_pulses.append(t)
            prev_out = out
        for name, count in expect.items():
            assert ctx.get(getattr(dut, name)) == count, name
        assert len(seen_pulses) == expect["pulses"] > 10 and expect["not_ready"] > 0 and expect["early"] > 0

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
