"""The whole Ethernet side (:class:`gateware.protocol.port.EthernetPort`) on its generated Verilog:
GMII pins to image rows and counters, replies back to GMII pins, under cocotb and Verilator
(:mod:`sim.tb.ethernet_tb`)."""

import pytest

from sim.harness import cocotb_run
from sim.tb.ethernet_pins import TOPLEVEL, build


@pytest.mark.verilog
def test_ethernet_verilog():
    cocotb_run.run(build("dlp7000"), toplevel=TOPLEVEL, module="sim.tb.ethernet_tb", key="dlp7000",
                   params={"dmd": "dlp7000"})
