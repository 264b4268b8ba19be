"""The sequencer's generated Verilog under cocotb and Verilator, on full XGA."""

import pytest

from gateware.dlpc410.facts import DMDS
from sim.harness import cocotb_run
from sim.tb.plane_source import SequencerBench


@pytest.mark.verilog
@pytest.mark.parametrize("mode,strict,order,depth", [
    ("GLOBAL", True, "MSB_FIRST", 8),     # every grey level 0..255
    ("SINGLE", False, "LSB_FIRST", 4),    # phased: 16 groups; a 4-bit frame keeps the run short
])
def test_sequencer_verilog_xga(mode, strict, order, depth):
    """One frame on full XGA, RST_ACTIVE and settle scaled down (run-time parameters)."""
    dmd = "dlp7000"
    bench = SequencerBench(DMDS[dmd], [(0, depth)])
    cocotb_run.run(bench, toplevel="dlpc410_sequencer_bench", module="sim.tb.seq_cocotb",
                   key=f"{dmd}-{depth}",
                   params={"dmd": dmd, "mode": mode, "strict": strict, "order": order,
                           "depth": depth,
                           "t_rst": 40, "t_settle": 80})
