"""The store's generated Verilog (serialiser, frame slots, writer, reader) under cocotb and
Verilator, with the MCB model's cocotb adapter on both ports (:mod:`sim.tb.store_tb`)."""

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
    cocotb_run.run(StoreChain(DMDS[dmd], slots=slots), toplevel="store_chain", module="sim.tb.store_tb",
                   key=dmd, params={"dmd": dmd, "slots": slots, "depths": depths, "extremes": extremes,
                                    "memory_bytes": memory}, testcase="every_bit_depth_and_extreme_images")


@pytest.mark.verilog
def test_store_verilog_sequence_beyond_the_live_slots():
    """A sequence over every slot of a store of 12 slots, 4 of them live: the slots beyond the
    live ones (their states in LUT RAM, their rows' sources not kept) on the generated Verilog."""
    slots, live = 12, 4
    memory = AddressMap(DMDS["test"], slots).end
    cocotb_run.run(StoreChain(DMDS["test"], slots=slots, live=live), toplevel="store_chain", module="sim.tb.store_tb",
                   key="sequence", params={"dmd": "test", "slots": slots, "live": live, "depths": [],
                                           "extremes": False, "memory_bytes": memory},
                   testcase="sequence_beyond_the_live_slots")
