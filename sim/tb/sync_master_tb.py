"""cocotb testbench of the sync master's generated Verilog: random software triggers and ready
lines, each board not ready now and then; every obeyed trigger must give one pulse of ``width``
cycles on every board's line at once and on the camera line, the cycle after the trigger, and every
refused one must be counted under its cause (:class:`sim.models.sync_master_model.SyncMasterModel`).

Run by ``tests/test_sync_master_verilog.py``.
"""

import random

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, FallingEdge, ReadOnly, RisingEdge

from gateware.registers import TriggerMode
from sim.harness.cocotb_run import params
from sim.models.sync_master_model import SyncMasterModel, scenario


@cocotb.test()
async def pulses_and_refusals(dut):
    p = params()
    boards, width, min_period, cycles = p["boards"], p["width"], p["min_period"], p["cycles"]
    triggers, ready_at = scenario(random.Random(p["seed"]), boards, cycles)
    model = SyncMasterModel(boards, min_period=min_period, stages=p["stages"])
    everyone = (1 << boards) - 1
    cocotb.start_soon(Clock(dut.clk, 8, unit="ns").start())
    for name, value in (("rst", 1), ("mode", TriggerMode.SOFTWARE.value), ("width", width),
                        ("min_period", min_period), ("period", 0), ("run", 1), ("trigger_in", 0),
                        ("soft", 0), ("ready", everyone)):
        getattr(dut, name).value = value
    await ClockCycles(dut.clk, 4)
    await FallingEdge(dut.clk)
    dut.rst.value = 0
    await ClockCycles(dut.clk, 4)        # the ready lines' synchroniser holds every board ready

    expected, started, high = [], [], 0
    for t in range(cycles):
        await FallingEdge(dut.clk)
        dut.ready.value = ready_at(t)
        dut.soft.value = int(t in triggers)
        await RisingEdge(dut.clk)
        await ReadOnly()
        if model.cycle(t, ready_at(t), t in triggers):
            expected.append(t + 1)
        out = dut.sync_out.value.to_unsigned()
        assert out in (0, everyone), f"cycle {t}: sync lines {out:b}, not all at once"
        assert bool(out) == bool(dut.camera_out.value), f"cycle {t}: camera line apart from the sync lines"
        if out:
            if not high:
                started.append(t)
            high += 1
        elif high:
            assert high == width, f"a pulse {high} cycles long, not {width}"
            high = 0
    # registered into the pads: each pulse leaves the cycle after its trigger
    assert started == expected, (started[:5], expected[:5])
    for name, count in model.counts.items():
        assert getattr(dut, name).value.to_unsigned() == count, (name, count)
    assert model.counts["pulses"] > 10 and model.counts["not_ready"] > 0 and model.counts["early"] > 0
