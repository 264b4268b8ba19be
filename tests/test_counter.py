"""The limbed event counter against a plain count: random increments and restarts (to a value
just below the wrap), with limbs small enough that every limb wraps many times, a limb of the
counter's whole width, and the count's own wrap."""

import random

import pytest
from amaranth.sim import Simulator

from gateware.counter import Counter


@pytest.mark.parametrize("width,limb_bits", [(10, 3), (9, 4), (11, 5), (5, 5)])
def test_count_is_exact_every_cycle(width, limb_bits, seed):
    restart_value = (1 << width) - 2
    dut = Counter(width, limb_bits=limb_bits, restart_value=restart_value)
    rng = random.Random(seed)
    steps = 3 * (1 << min(width, 11))
    checked = [0]

    async def bench(ctx):
        count = 0
        for _ in range(steps):
            inc = rng.random() < 0.8
            restart = rng.random() < 0.01
            ctx.set(dut.inc, inc)
            ctx.set(dut.restart, restart)
            await ctx.tick()
            count = restart_value if restart else (count + inc) % (1 << width)
            assert ctx.get(dut.count) == count
            checked[0] += 1

    sim = Simulator(dut)
    sim.add_clock(5e-9)
    sim.add_testbench(bench)
    sim.run()
    assert checked[0] == steps
