"""cocotb tests that must fail: proof that a failing cocotb test fails the pytest that ran it."""

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles


@cocotb.test()
async def wrong_expectation(dut):
    cocotb.start_soon(Clock(dut.clk, 8, unit="ns").start())
    dut.rst.value = 0
    await ClockCycles(dut.clk, 2)
    assert int(dut.count.value) == 1_000_000, "deliberately false"
