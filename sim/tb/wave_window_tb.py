"""cocotb stimulus of the wave window's test (``tests/test_wave_window.py``): the clock runs, the
window is held open from ``open_ns`` to ``close_ns``, then the run goes on as long again."""

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import Timer

from sim.harness.cocotb_run import params


@cocotb.test()
async def window(dut):
    p = params()
    dut.wave_dump.value = 0
    Clock(dut.clk, 10, unit="ns").start()
    await Timer(p["open_ns"], "ns")
    dut.wave_dump.value = 1
    await Timer(p["close_ns"] - p["open_ns"], "ns")
    dut.wave_dump.value = 0
    await Timer(p["close_ns"], "ns")
