"""The transmit MAC's generated Verilog (AXI-Stream wrapper) under cocotb and Verilator
(:mod:`sim.tb.mac_tx_tb`)."""

import pytest

from gateware.mac.axis import AxisTransmitter
from sim.harness import cocotb_run


@pytest.mark.verilog
def test_mac_tx_verilog():
    cocotb_run.run(AxisTransmitter(), toplevel="mac_axis_tx", module="sim.tb.mac_tx_tb", key="default")
