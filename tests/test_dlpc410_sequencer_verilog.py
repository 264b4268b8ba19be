"""The sequencer's generated Verilog under cocotb and Verilator, on full XGA."""

import pytest

from sim.harness import cocotb_run
from sim.tb.plane_source import SequencerBench
from spec.facts import DMDS


@pytest.mark.verilog
@pytest.mark.parametrize("dmd,mode,strict,order,depth", [
    ("dlp7000", "GLOBAL", True, "MSB_FIRST", 8),     # every grey level 0..255
    ("dlp7000", "SINGLE", False, "LSB_FIRST", 4),    # phased: 16 groups; 4 bits keep it short
    ("test4", "QUAD", True, "MSB_FIRST", 8),         # four buses (DIN_A..D), 1080p-style clears
])
def test_sequencer_verilog_xga(dmd, mode, strict, order, depth):
    """One frame on full XGA (and on the small four-bus geometry), RST_ACTIVE and settle scaled
    down (run-time parameters)."""
    bench = SequencerBench(DMDS[dmd], [(0, depth)])
    cocotb_run.run(bench, toplevel="dlpc410_sequencer_bench", module="sim.tb.seq_cocotb",
                   key=f"{dmd}-{depth}",
                   params={"dmd": dmd, "mode": mode, "strict": strict, "order": order,
                           "depth": depth,
                           "t_rst": 40, "t_settle": 80})
