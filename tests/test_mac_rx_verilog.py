"""The receive MAC's generated Verilog (AXI-Stream wrapper) under cocotb and Verilator
(:mod:`sim.tb.mac_rx_tb`)."""

import pytest

from gateware.mac.axis import AxisReceiver
from sim.harness import cocotb_run


@pytest.mark.verilog
def test_mac_rx_verilog():
    cocotb_run.run(AxisReceiver(), toplevel="mac_axis_rx", module="sim.tb.mac_rx_tb", key="default",
                   params={"max_frame": 9018})
