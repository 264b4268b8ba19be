"""cocotb testbench: the DLPC410 model's cocotb adapter on the replay component's Verilog.

The same cycles fed straight to the model give the reference; through the adapter the legal
sequence must give the same command log and mirrors, the illegal one the same named rule break.

Run by ``tests/test_dlpc410_adapters.py``.
"""

import cocotb
import numpy as np
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, RisingEdge, with_timeout

from sim.harness.cocotb_run import params
from sim.models.dlpc410_model import RULES, CocotbAdapter, Dlpc410, RuleBreak
from sim.models.dlpc410_replay import MODEL_PARAMS, NAMES, sequences
from spec.facts import DMDS


def relative(log, origin):
    return [(c.cycle - origin, c.kind, c.blocks, c.row, c.mode) for c in log]


async def start(dut, name):
    dmd = DMDS[params()["dmd"]]
    dut.select.value = NAMES.index(name)
    cocotb.start_soon(Clock(dut.clk, 5, unit="ns").start())
    model = Dlpc410(dmd, **MODEL_PARAMS)
    task = cocotb.start_soon(CocotbAdapter(model, dut, dut.clk).run())
    dut.rst.value = 1
    await ClockCycles(dut.clk, 3)
    dut.rst.value = 0
    reference = Dlpc410(dmd, **MODEL_PARAMS)
    return model, reference, task


@cocotb.test()
async def legal_sequence(dut):
    model, reference, task = await start(dut, "legal")
    reference.run(sequences(model.dmd)["legal"])
    await with_timeout(RisingEdge(dut.done), 100, "us")
    await ClockCycles(dut.clk, 4)
    task.cancel()
    assert model.log
    assert relative(model.log, model.arstz_rise) == relative(reference.log, reference.arstz_rise)
    assert np.array_equal(model.mirrors, reference.mirrors)
    assert np.array_equal(model.memory, reference.memory)
    assert [c.mode for c in model.log if c.kind == "pulse"] == ["global", "single", "dual"]


@cocotb.test()
async def illegal_sequence(dut):
    model, reference, task = await start(dut, "illegal")
    try:
        reference.run(sequences(model.dmd)["illegal"])
    except RuleBreak as e:
        want = e
    try:
        await with_timeout(task, 100, "us")
    except RuleBreak as e:
        assert e.rule is RULES["rst_active"], str(e)
        assert e.cycle - model.arstz_rise == want.cycle - reference.arstz_rise
    else:
        raise AssertionError("the adapter let a pulse during RST_ACTIVE through")
