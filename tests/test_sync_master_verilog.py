"""The sync master's generated Verilog under cocotb against the plain model
(:mod:`sim.tb.sync_master_tb`)."""

import pytest

from gateware.sync.master import SyncMaster
from sim.harness import cocotb_run


@pytest.mark.verilog
@pytest.mark.parametrize("boards", [4, 12])     # four tiles; three groups of four
def test_sync_master_verilog(boards, seed):
    cocotb_run.run(SyncMaster(boards), toplevel="sync_master", module="sim.tb.sync_master_tb", key=str(boards),
                   params={"boards": boards, "width": 3, "min_period": 40, "cycles": 3100, "stages": 2,
                           "seed": seed})
