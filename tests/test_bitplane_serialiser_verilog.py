"""The bit-plane serialiser's generated Verilog under cocotb and Verilator
(:mod:`sim.tb.serialiser_tb`)."""

import pytest

from gateware.bitplane import Serialiser
from sim.harness import cocotb_run
from spec.facts import DMDS


@pytest.mark.verilog
@pytest.mark.parametrize("lanes", [1, 8])
def test_serialiser_verilog(lanes):
    dmd = "test"
    cocotb_run.run(Serialiser(DMDS[dmd], lanes=lanes), toplevel="bitplane_serialiser",
                   module="sim.tb.serialiser_tb", key=f"{dmd}-{lanes}",
                   params={"dmd": dmd, "lanes": lanes})
