"""cocotb tests that fail: proof that a failing cocotb test fails the pytest that ran it, and that
concurrent runs of one build report their own results. Run by
``tests/test_harness.py``."""

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles


@cocotb.test()
async def wrong_expectation(dut):
    cocotb.start_soon(Clock(dut.clk, 8, unit="ns").start())
    dut.rst.value = 0
    await ClockCycles(dut.clk, 2)
    assert int(dut.count.value) == 1_000_000, "deliberately false"


@cocotb.test()
async def fail_as_told(dut):
    """Runs ``cycles`` cycles, then fails if the parameters say ``fail``."""
    from sim.harness.cocotb_run import params

    p = params()
    cocotb.start_soon(Clock(dut.clk, 8, unit="ns").start())
    dut.rst.value = 0
    await ClockCycles(dut.clk, p["cycles"])
    assert not p["fail"], "told to fail"
