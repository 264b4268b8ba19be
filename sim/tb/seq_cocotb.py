"""cocotb testbench of the sequencer's generated Verilog under the rule-checking DLPC410 model.

One triggered frame (bit depth from the parameters) of the ramp image (every grey level on
every row) on the DMD named in the parameters, with RST_ACTIVE and settle scaled down. The
DLPC410 model (:class:`sim.models.dlpc410.CocotbAdapter`) drives ECP2_FINISHED, INIT_ACTIVE and
RST_ACTIVE and raises on any broken rule; its command log must equal the schedule model's cycle
for cycle, and the camera model must see every pixel integrate exactly its grey level.
"""

import cocotb
import numpy as np
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, FallingEdge

from gateware.dlpc410.trigger import PIN_TO_STROBE
from gateware.registers import Registers
from sim.harness.cocotb_run import params
from sim.harness.layout import pack
from sim.models.dlpc410 import CocotbAdapter
from sim.tb.plane_source import ramp_image
from sim.tb.seq_sim import dlpc410_for, frame_lights
from spec import schedule
from spec.facts import DMDS
from spec.registers import PlaneOrder, ResetMode


def plan_from(prm):
    dmd = DMDS[prm["dmd"]]
    return dmd, schedule.plan(dmd, 200e6, t_rst_s=prm["t_rst"] / 200e6, t_settle_s=prm["t_settle"] / 200e6,
                              reset_mode=ResetMode[prm["mode"]], strict_rst=prm["strict"],
                              order=PlaneOrder[prm["order"]], depth=prm["depth"]).params


@cocotb.test()
async def ramp_frame_matches_model(dut):
    prm = params()
    dmd, p = plan_from(prm)
    depth = prm["depth"]
    frames = [schedule.Frame(0, depth)]   # repeated: a newer frame offered while waiting would be reloaded
    ready = max(g.loaded_at for g in schedule.simulate(dmd, p, frames[:1]).groups)
    pin = ready + 6
    model_run = schedule.simulate(dmd, p, frames, [pin + PIN_TO_STROBE])
    end = model_run.commands[-1][0] + 64

    cocotb.start_soon(Clock(dut.clk, 5, unit="ns").start())
    dut.regs.value = pack(Registers, p.registers(dmd))
    dut.trigger_in.value = 0
    dut.release__ready.value = 1
    dut.rst.value = 1
    await ClockCycles(dut.clk, 3)
    dut.rst.value = 0
    # the controller from the first cycle out of reset: it drives INIT_ACTIVE, ECP2_FINISHED,
    # RST_ACTIVE and checks the training pattern
    model = dlpc410_for(dmd, p)
    cocotb.start_soon(CocotbAdapter(model, dut, dut.clk, prefix="pins__").run())

    # mid-cycle (falling edge) every output is stable and the model has not stepped this cycle
    now_mask = (1 << 48) - 1
    now = shift = 0
    high_left = 0
    last_sync = 0
    windows = []
    while now < end:
        await FallingEdge(dut.clk)
        now = dut.status.value.to_unsigned() & now_mask
        if not now:
            continue
        shift = now - model.cycle
        sync = int(dut.sync_out.value)
        if sync != last_sync:
            if sync:
                windows.append([model.cycle, None])
            else:
                windows[-1][1] = model.cycle
            last_sync = sync
        # the trigger pin is high during cycles ``pin`` .. ``pin + 3`` of the time base
        if now == pin:
            high_left = 4
        dut.trigger_in.value = int(high_left > 0)
        high_left = max(0, high_left - 1)
    got = [c for c in model.commands(shift - 1) if c[0] < end]
    want = [c for c in model_run.decoded() if c[0] < end]
    first = next((i for i, (x, y) in enumerate(zip(got, want, strict=False)) if x != y), None)
    where = None if first is None else (got[first], want[first])
    assert got == want, f"{len(got)} vs {len(want)} commands; first difference at {first}: {where}"
    assert len(windows) == 1 and windows[0][1] is not None, f"one frame expected: {windows}"
    (light,) = frame_lights(model, windows)
    expect = (ramp_image(dmd, 0).astype(np.int64) >> (8 - depth)) * p.lsb
    assert np.array_equal(light, expect), f"max error {np.abs(light - expect).max() / p.lsb} LSB"
    dut._log.info("%d commands equal, %d pixels exact, no rule broken", len(got), light.size)
