"""The endpoint's generated Verilog under cocotb and Verilator (:mod:`sim.tb.endpoint_tb`)."""

import pytest

from gateware.protocol.endpoint import Endpoint
from sim.harness import cocotb_run
from sim.models.frames import Addresses
from spec.facts import DMDS


@pytest.mark.verilog
def test_endpoint_verilog():
    dmd = "test"
    a = Addresses()
    cocotb_run.run(Endpoint(DMDS[dmd], mac=a.mac, ip=a.ip, port=a.port), toplevel="endpoint",
                   module="sim.tb.endpoint_tb", key=dmd, params={"dmd": dmd})
