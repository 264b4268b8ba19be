"""The segmented countdown timer against a plain model of its definition: loaded with ``v`` at
cycle ``c``, its time is ``T = c + v - lag``; ``done`` is ``t >= T``, ``late`` is ``t > T + slack``,
``within[k]`` is ``T - t < k``, ``ends`` is ``t == T + lag``. Random loads of values of every
size, including ones that make each limb borrow and wrap, and long runs to zero."""

import random

import pytest
from amaranth.sim import Simulator

from gateware.countdown import Countdown


@pytest.mark.parametrize("lag,slack,flags", [(0, 0, "value"), (1, 1, "value"), (2, 1, "value"), (3, 0, "value"),
                                              (1, 1, "settled"), (0, 0, "settled")])
def test_flags_follow_the_definition(lag, slack, flags):
    """(``settled``: the value is set the cycle before its load, and held through it.)"""
    width = 40
    ks = (3, 17, 300)
    dut = Countdown(width, within=ks, lag=lag, slack=slack, flags=flags)
    rng = random.Random(11)
    checked = [0]

    async def bench(ctx):
        t = 0
        target = None              # T of the last load (None: never loaded: done and late)
        values = [0, 1, 2, 3, 16, 17, 299, 300, 301, 0xFFFF, 0x10000, 0x10001, 0x1FFFF, 0x20000]
        for step in range(4000):
            load = rng.random() < 0.03 or step < 30
            if load:
                v = rng.choice(values) if rng.random() < 0.7 else rng.randrange(0, 1 << rng.choice((4, 12, 17, 20)))
                ctx.set(dut.value, v)
                if flags == "settled":
                    await ctx.tick()
                    t += 1
                    if target is not None:
                        assert ctx.get(dut.done) == (t >= target)
                ctx.set(dut.load, 1)
            await ctx.tick()
            ctx.set(dut.load, 0)
            if load:
                target = t + v - lag
            t += 1
            done, late, within = ctx.get(dut.done), ctx.get(dut.late), ctx.get(dut.within)
            if target is None:
                assert done and late
            else:
                assert done == (t >= target), (t, target)
                assert late == (t > target + slack), (t, target)
                assert ctx.get(dut.ends) == (t == target + lag), (t, target)
                for i, k in enumerate(ks):
                    assert bool(within >> i & 1) == (target - t < k), (t, target, k)
            checked[0] += 1

    sim = Simulator(dut)
    sim.add_clock(5e-9)
    sim.add_testbench(bench)
    sim.run()
    assert checked[0] == 4000


def test_long_count_through_the_limbs():
    """0x20002 counted down to done: every limb borrows and wraps on the way."""
    dut = Countdown(40)

    async def bench(ctx):
        ctx.set(dut.load, 1)
        ctx.set(dut.value, 0x20002)
        await ctx.tick()
        ctx.set(dut.load, 0)
        cycles = 1
        while not ctx.get(dut.done):
            await ctx.tick()
            cycles += 1
        assert cycles == 0x20002
        assert not ctx.get(dut.late)
        await ctx.tick()
        assert ctx.get(dut.late)

    sim = Simulator(dut)
    sim.add_clock(5e-9)
    sim.add_testbench(bench)
    sim.run()
