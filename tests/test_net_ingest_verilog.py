"""The ingest block's generated Verilog under cocotb and Verilator."""

import pytest

from gateware.dlpc410.facts import DMDS
from gateware.net.ingest import Ingest
from sim.harness import cocotb_run
from sim.models.frames import Addresses


@pytest.mark.verilog
def test_ingest_verilog():
    dmd = "test"
    a = Addresses()
    cocotb_run.run(Ingest(DMDS[dmd], mac=a.mac, ip=a.ip, port=a.port), toplevel="net_ingest",
                   module="sim.tb.ingest", key=dmd, params={"dmd": dmd})
