"""cocotb: the DLPC410 responder and the pin recorder
(:class:`sim.rigs.fast_system_rig.ResponderBench`) on a replayed cycle sequence; the trace is
checked afterwards (:mod:`sim.models.trace`) by the test that runs it,
``tests/test_trace_replay.py``."""

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, RisingEdge, with_timeout

from sim.harness.cocotb_run import params


@cocotb.test()
async def record_sequence(dut):
    dut.select.value = params()["select"]
    dut.flush.value = 0
    dut.rst.value = 1
    Clock(dut.clk, 5, unit="ns").start()
    await ClockCycles(dut.clk, 3)
    dut.rst.value = 0
    await with_timeout(RisingEdge(dut.done), 100, "us")
    await ClockCycles(dut.clk, 4)
    dut.flush.value = 1
    await ClockCycles(dut.clk, 2)
