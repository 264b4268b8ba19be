"""The planner's parts that stand on their own: ``at_least_two`` (the planner's "two groups or
more play") against a count of the bits, every value of small widths and random 16-bit ones."""

import random

import pytest
from amaranth import Module, Signal
from amaranth.sim import Simulator

from gateware.dlpc410.planner import at_least_two


@pytest.mark.parametrize("width", [1, 2, 3, 5, 8, 16])
def test_at_least_two_is_a_count_of_two(width, seed):
    bits = Signal(width)
    two = Signal()
    rng = random.Random(seed)
    values = range(1 << width) if width <= 8 else [rng.getrandbits(width) for _ in range(2000)] + \
        [1 << k for k in range(width)] + [0, (1 << width) - 1]
    checked = []

    async def bench(ctx):
        for value in values:
            ctx.set(bits, value)
            got = ctx.get(two)
            assert got == (bin(value).count("1") >= 2), f"{value:0{width}b}"
            checked.append(got)

    m = Module()
    m.d.comb += two.eq(at_least_two(bits))
    sim = Simulator(m)
    sim.add_testbench(bench)
    sim.run()
    assert len(checked) == len(values) and (width < 2 or any(checked)) and not all(checked)
