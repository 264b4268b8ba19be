"""The SVEC's Ethernet on its generated Verilog: MAC, our PCS and the GTP lane's model against an
independent Python link partner on its own clock (:mod:`sim.tb.sfp_link_tb`), with the partner
100 ppm fast and the core 100 ppm slow, and the other way round."""

import pytest

from sim.harness import cocotb_run
from sim.tb.sfp_link import BUILD_ARGS, SOURCES, TOPLEVEL, SfpLink, plusargs


def _verilog():
    return cocotb_run.converted(SfpLink, TOPLEVEL, "default")


@pytest.mark.verilog
@pytest.mark.parametrize("ppm, offset", [(100, 3), (-100, 8)])
def test_sfp_link_verilog(ppm, offset):
    cocotb_run.run(_verilog(), toplevel=TOPLEVEL, module="sim.tb.sfp_link_tb", key="default",
                   params={"offset": offset, "seed": offset}, extra_sources=SOURCES, build_args=BUILD_ARGS,
                   plusargs=plusargs(partner_ppm=ppm, core_ppm=-ppm))
