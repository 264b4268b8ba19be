"""cocotb testbench of the VCXO DAC writer's generated Verilog: trim words changing now and then
(some during a write), the lines sampled every cycle through the AD5662's interface model
(:class:`sim.models.ad5662_model.TrimWrites`): every write whole, the word of the cycle it began on.

Run by ``tests/test_sync_trim_dac.py``.
"""

import random

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, FallingEdge, ReadOnly, RisingEdge

from sim.harness.cocotb_run import params
from sim.models.ad5662_model import TrimWrites, trim_scenario


@cocotb.test()
async def every_word_whole(dut):
    p = params()
    cycles, period_ns = p["cycles"], 1e9 / p["clk_hz"]
    changes = trim_scenario(random.Random(p["seed"]), cycles)
    writes = TrimWrites(period_ns)
    cocotb.start_soon(Clock(dut.clk, period_ns, unit="ns").start())
    dut.rst.value, dut.trim.value = 1, 0
    await ClockCycles(dut.clk, 3)
    await FallingEdge(dut.clk)
    dut.rst.value = 0
    trim = 0
    for t in range(cycles):
        trim = changes.get(t, trim)
        dut.trim.value = trim
        await RisingEdge(dut.clk)
        await ReadOnly()
        writes.cycle(t, trim, *(int(getattr(dut, name).value) for name in ("sclk", "din", "sync_n")))
        await FallingEdge(dut.clk)
    done = writes.check()
    assert done >= cycles // (4 * 50) - 1, done
