"""The sequencer's generated Verilog under cocotb and Verilator, on full XGA."""

import pytest

from gateware.dlpc410.facts import DMDS
from sim.harness import cocotb_run
from sim.tb.plane_source import SequencerBench


@pytest.mark.verilog
@pytest.mark.parametrize("mode,strict,order", [
    ("GLOBAL", True, "MSB_FIRST"),
    ("SINGLE", False, "LSB_FIRST"),
])
def test_sequencer_verilog_xga(mode, strict, order):
    dmd = "dlp7000"
    bench = SequencerBench(DMDS[dmd], [(0, 8), (1, 8)])
    cocotb_run.run(bench, toplevel="dlpc410_sequencer_bench", module="sim.tb.seq_cocotb", key=dmd,
                   params={"dmd": dmd, "mode": mode, "strict": strict, "order": order,
                           "t_rst": 40, "t_settle": 80})
