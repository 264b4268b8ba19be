"""cocotb: the GMII replay plays its file cycle for cycle (run by ``tests/test_gmii_replay.py``)."""

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, RisingEdge

from sim.harness.cocotb_run import params


@cocotb.test()
async def plays_file(dut):
    p = params()
    expected = [tuple(c) for c in p["cycles"]]
    cocotb.start_soon(Clock(dut.clk, 8, unit="ns").start())
    dut.start.value = 0
    await ClockCycles(dut.clk, 2)
    dut.start.value = 1
    await RisingEdge(dut.clk)
    dut.start.value = 0
    got = []
    await RisingEdge(dut.clk)
    while int(dut.busy.value):
        await RisingEdge(dut.clk)
        if int(dut.busy.value):
            got.append((int(dut.rx_dv.value), int(dut.rx_er.value), int(dut.rx_d.value)))
    assert got == expected, f"{len(got)} cycles played, {len(expected)} in the file"
