"""cocotb testbench of the sequencer's generated Verilog (with the plane-source fixture).

One triggered frame (bit depth from the parameters) of the ramp image (every grey level on
every row) on the DMD named in the parameters, with RST_ACTIVE and settle scaled down: the
decoded command stream must equal the schedule model's cycle for cycle, and every pixel must
integrate exactly its grey level.
"""

import cocotb
import numpy as np
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, RisingEdge

from gateware.dlpc410 import schedule
from gateware.dlpc410.facts import DMDS, BlockMode
from gateware.dlpc410.params import PlaneOrder, Registers, ResetMode
from gateware.dlpc410.trigger import PIN_TO_STROBE
from sim.harness.cocotb_run import params
from sim.harness.layout import pack
from sim.models.dlpc410_commands import CommandDecoder
from sim.tb.plane_source import ramp_image


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
    model = schedule.simulate(dmd, p, frames, [pin + PIN_TO_STROBE])
    end = model.commands[-1][0] + 64

    cocotb.start_soon(Clock(dut.clk, 5, unit="ns").start())
    dut.regs.value = pack(Registers, p.registers(dmd))
    dut.pins__ecp2_finished.value = 1
    dut.pins__init_active.value = 1
    dut.pins__rst_active.value = 0
    dut.trigger_in.value = 0
    dut.release__ready.value = 1
    dut.rst.value = 1
    await ClockCycles(dut.clk, 3)
    dut.rst.value = 0
    await ClockCycles(dut.clk, 20)
    dut.pins__init_active.value = 0

    decoder = CommandDecoder(dmd)
    now_mask = (1 << 48) - 1
    now = 0
    while now == 0:
        await RisingEdge(dut.clk)
        now = dut.status.value.to_unsigned() & now_mask
    rst_left = high_left = 0
    light = None
    last_sync = 0
    while now < end:
        if dut.pins__dvalid.value:
            a = dut.pins__din_a.value.to_unsigned()
            b = dut.pins__din_b.value.to_unsigned()
            blkmd = int(dut.pins__blkmd.value)
            lanes = {("A", "rise"): a & 0xffff, ("A", "fall"): a >> 16,
                     ("B", "rise"): b & 0xffff, ("B", "fall"): b >> 16}
            decoder.step(now - 1, 1, int(dut.pins__rowmd.value), int(dut.pins__rowad.value), blkmd,
                         int(dut.pins__blkad.value), int(dut.pins__rst2blkz.value), lanes)
            if blkmd in (BlockMode.RESET, BlockMode.MULTI) and decoder._beat == 1:
                rst_left = p.t_rst - schedule.RST_MARGIN
        else:
            decoder.step(now - 1, 0, 0, 0, 0, 0, 1, None)
        sync = int(dut.sync_out.value)
        if sync != last_sync and not sync:
            light = decoder.take_light()
        last_sync = sync
        if now + 1 == pin:
            high_left = 4
        dut.trigger_in.value = int(high_left > 0)
        high_left = max(0, high_left - 1)
        dut.pins__rst_active.value = int(rst_left > 0)
        rst_left = max(0, rst_left - 1)
        await RisingEdge(dut.clk)
        now += 1
    assert dut.status.value.to_unsigned() & now_mask == now, "lost track of the time base"
    got = decoder.commands
    want = [c for c in model.commands if c[0] < end]
    first = next((i for i, (x, y) in enumerate(zip(got, want, strict=False)) if x != y), None)
    where = None if first is None else (got[first], want[first])
    assert got == want, f"{len(got)} vs {len(want)} commands; first difference at {first}: {where}"
    assert light is not None, "the frame did not end"
    assert np.array_equal(light, (ramp_image(dmd, 0).astype(np.int64) >> (8 - depth)) * p.lsb)
    dut._log.info("%d commands equal, %d pixels exact", len(got), light.size)
