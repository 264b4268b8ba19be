"""The board's clock loop (:class:`gateware.sync.clock_trim.ClockTrim`) against its model
(:mod:`sim.models.clock_trim_model`, written from the description): pulses arrive before or after
the falling edge of a cycle, near where they are expected, far from it (saturating each term), and
beyond the capture range (a slip); after each the phase, the trim word, the lock and the counts must
be the model's. The model's loop also locks a VCXO from 100 ppm off at every period the gains are
chosen for."""

import random

import numpy as np
import pytest
from amaranth import ClockDomain, ClockSignal, Module, Signal
from amaranth.sim import Simulator

from gateware.sync.clock_trim import ClockTrim, gains
from sim.models.clock_trim_model import ClockTrimModel, lock, loop_gains

PERIOD_NS = 10
#: The time base when the pulse is seen, after the falling edge that sampled it: the
#: synchroniser's two stages.
SEEN_AFTER = 2
#: Cycles the loop's steps take after a pulse, at most (the terms doubled up to 15 times).
SETTLE = 30


def _arrivals(rng, period):
    """``(cycles after the last pulse, after the falling edge?)`` of each pulse (None: a period
    and one to the other side of the expected cycle)."""
    steps = [None] * 20                    # dithering across the expected cycle: locks
    steps += [period + rng.choice((-1, 0, 0, 1)) for _ in range(30)]      # near lock
    steps += [period + 700, period - 650]                                  # far: each term saturates
    steps += [2 * period]                                                   # a pulse missed: a slip
    steps += [period + rng.randint(-3, 3) for _ in range(30)]
    return [(step, k >= 20 and rng.random() < 0.5) for k, step in enumerate(steps)]


@pytest.mark.parametrize("pad", [False, True], ids=["sampled_here", "sampled_in_pad"])
def test_clock_trim_follows_its_model(pad):
    """``pad``: the falling-edge sample taken before the loop (as a board's DDR input register's
    falling half), the loop built to take it (``sampled``)."""
    period = 1000
    m = Module()
    m.submodules.dut = dut = ClockTrim(sampled=pad)
    line = Signal()                     # the sync line
    if pad:
        m.domains.fall = ClockDomain("fall", clk_edge="neg")
        m.d.comb += ClockSignal("fall").eq(ClockSignal("sync"))
        m.d.fall += dut.sync_in.eq(line)
    else:
        m.d.comb += dut.sync_in.eq(line)
    now = Signal(16, init=0xFFF0)       # wraps during the run
    m.d.sync += now.eq(now + 1)
    m.d.comb += dut.now.eq(now)
    model = ClockTrimModel(period)
    rng = random.Random(7)
    checked = []

    async def bench(ctx):
        ctx.set(dut.period, period)
        await ctx.tick().repeat(8)
        for step, late in [(50, False), *_arrivals(rng, period)]:
            if step is None:        # to the other side of the expected cycle
                step = period - 1 if model.phase == 0 else period + 1
            await ctx.tick().repeat(step - SETTLE - 4)
            # mid-cycle: before the falling edge, or after it (then the next one samples it)
            await ctx.delay(PERIOD_NS * (0.75 if late else 0.25) * 1e-9)
            sampled = (ctx.get(now) + late) & 0xFFFF
            ctx.set(line, 1)
            await ctx.tick().repeat(4)
            ctx.set(line, 0)
            await ctx.tick().repeat(SETTLE)
            model.pulse((sampled + SEEN_AFTER) & 0xFFFF)
            got = {name: ctx.get(getattr(dut, name)) for name in ("phase", "trim", "locked", "pulses", "slips")}
            want = {"phase": model.phase, "trim": model.trim, "locked": int(model.locked), "pulses": model.pulses,
                    "slips": model.slips}
            assert got == want, (len(checked), got, want)
            checked.append(got)
        ctx.set(dut.period, 0)
        await ctx.tick().repeat(3)
        assert ctx.get(dut.trim) == 0, "off: no pull"

    sim = Simulator(m)
    sim.add_clock(PERIOD_NS * 1e-9)
    sim.add_testbench(bench)
    sim.run()
    trims = [c["trim"] for c in checked]
    assert any(c["locked"] for c in checked) and checked[-1]["slips"] == 1
    assert min(trims) < -20000 and max(trims) > 20000, "the far pulses saturate the terms"


def test_gains_match_the_model():
    for period in (100, 1568, 16_900, 731_900, 1 << 23):
        assert gains(period) == loop_gains(period)


def test_loop_locks_a_vcxo_at_every_period():
    """From 100 ppm off, either way, at the small DMD's 4- and 8-plane periods and the DLP7000's
    8-bit frame: locked within 200 pulses, the edge then within 0.1 cycle of the falling edge."""
    for period in (1568, 16_900, 731_900):
        for ppm in (100, -100, 37):
            trace = np.array(lock(period, ppm, pulses=400))
            settled = trace[200:]
            assert settled[:, 0].max() < 0.1, (period, ppm, settled[:, 0].max())
            assert np.abs(settled[:, 1]).max() < 60, (period, ppm)
