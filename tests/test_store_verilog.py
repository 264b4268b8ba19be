"""The store's generated Verilog (serialiser, frame slots, writer, reader) under cocotb and
Verilator, with the MCB model's cocotb adapter on both ports."""

import pytest

from gateware.store.addresses import AddressMap
from sim.harness import cocotb_run
from sim.tb.store_chain import StoreChain
from spec.facts import DMDS


@pytest.mark.verilog
@pytest.mark.parametrize("dmd, depths, extremes", [
    ("test", list(range(1, 9)), True),
    pytest.param("dlp7000", [2], False, marks=pytest.mark.slow),    # one full XGA frame
])
def test_store_verilog(dmd, depths, extremes):
    slots = 4
    memory = AddressMap(DMDS[dmd], slots).end
    cocotb_run.run(StoreChain(DMDS[dmd], slots=slots), toplevel="store_chain", module="sim.tb.store",
                   key=dmd, params={"dmd": dmd, "slots": slots, "depths": depths, "extremes": extremes,
                                    "memory_bytes": memory})
