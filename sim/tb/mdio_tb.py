"""cocotb: the PHY management block's Verilog against the clause-22 PHY model (run by
``tests/test_mac_mdio.py``)."""

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, RisingEdge

from gateware.mac.mdio import LinkStatus
from sim.harness.cocotb_run import params
from sim.harness.layout import unpack
from sim.models.mdio_phy_model import MdioPhy


@cocotb.test()
async def polls_status(dut):
    p = params()
    phy = MdioPhy(p["phy_address"], {17: p["status_word"]})
    cocotb.start_soon(Clock(dut.clk, 8, unit="ns").start())
    dut.rst.value = 1
    dut.mdio_i.value = 1
    await ClockCycles(dut.clk, 2)
    dut.rst.value = 0
    for _ in range(20000):
        await RisingEdge(dut.clk)
        dut.mdio_i.value = phy.step(int(dut.mdc.value), int(dut.mdio_o.value), int(dut.mdio_oe.value))
        if unpack(LinkStatus, int(dut.status.value))["polls"] >= p["polls"]:
            break
    status = unpack(LinkStatus, int(dut.status.value))
    assert status == {"up": 1, "speed": 2, "resolved": 1, "polls": p["polls"]}, status
    assert phy.reads == [(p["phy_address"], 17)] * p["polls"]
