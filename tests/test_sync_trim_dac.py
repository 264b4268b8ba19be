"""The VCXO DAC writer (:class:`gateware.sync.trim_dac.TrimDac`) seen through the AD5662's interface
(:mod:`sim.models.ad5662_model`, written from the data sheet): every write carries the trim word of
the cycle it began on, whole, in offset binary, within the DAC's timing, at 200 MHz and at a slower
clock; in the Amaranth simulation and on the generated Verilog (:mod:`sim.tb.trim_dac_tb`)."""

import random

import pytest
from amaranth.sim import Simulator

from gateware.sync.trim_dac import TrimDac, gap_halves, half_period_cycles
from sim.harness import cocotb_run
from sim.models.ad5662_model import Ad5662, TimingError, TrimWrites, trim_scenario

CYCLES = 12_000


def test_half_period_keeps_the_dac_rate():
    # 200 MHz: 4 cycles a half (25 MHz, under the DAC's 30); 62.5 MHz: 2 (15.6 MHz)
    assert (half_period_cycles(200e6), gap_halves(200e6)) == (4, 2)
    assert (half_period_cycles(62.5e6), gap_halves(62.5e6)) == (2, 2)


@pytest.mark.parametrize("clk_hz", [200e6, 62.5e6])
def test_trim_dac_writes_every_word_whole(clk_hz):
    dut = TrimDac(clk_hz)
    period_ns = 1e9 / clk_hz
    changes = trim_scenario(random.Random(3), CYCLES)
    writes = TrimWrites(period_ns)

    async def bench(ctx):
        trim = 0
        for t in range(CYCLES):
            trim = changes.get(t, trim)
            ctx.set(dut.trim, trim)
            await ctx.tick()
            writes.cycle(t, trim, *(ctx.get(s) for s in (dut.sclk, dut.din, dut.sync_n)))

    sim = Simulator(dut)
    sim.add_clock(period_ns * 1e-9)
    sim.add_testbench(bench)
    sim.run()
    half, gap = half_period_cycles(clk_hz), gap_halves(clk_hz)
    assert writes.check() >= CYCLES // (half * (gap + 48)) - 1


def test_dac_model_catches_a_fast_clock_and_a_short_write():
    """The oracle is not blind: SCLK at 50 MHz breaks its timing, SYNC rising early abandons."""
    dac = Ad5662()
    with pytest.raises(TimingError):
        for k in range(8):
            dac.sample(10 * k, k % 2 == 0, 0, 0 if k else 1)
    dac = Ad5662()
    t = 0
    for level in [(1, 1, 1), (1, 1, 0)] + [(k % 2, 1, 0) for k in range(10)] + [(1, 1, 1)]:
        t += 40
        dac.sample(t, *level)
    assert dac.abandoned == 1 and dac.codes == []


@pytest.mark.verilog
def test_trim_dac_verilog(seed):
    cocotb_run.run(TrimDac(200e6), toplevel="trim_dac", module="sim.tb.trim_dac_tb", key="200mhz",
                   params={"cycles": CYCLES, "seed": seed, "clk_hz": 200e6})
