"""The projector's core end to end on its generated Verilog: GMII in, DLPC410 model out."""

import json

import pytest

from gateware.dlpc410.facts import DMDS
from gateware.top.system import Projector
from sim.harness import cocotb_run
from sim.harness.paths import build_dir

MAC, IP, PORT = 0x02_00_00_00_00_01, 0x0A_00_00_02, 5000


def system_params(dmd, **overrides):
    p = {"dmd": dmd, "mac": "02:00:00:00:00:01", "ip": "10.0.0.2", "port": PORT,
         "memory_bytes": 4 * 2**20, "t_rst": 40, "t_settle": 60, "init_cycles": 200,
         "init_grace": 4, "mode": "GLOBAL", "order": "MSB_FIRST", "frames": 1, "seed": 1,
         "settle_after_send": 3000}
    p.update(overrides)
    return p


@pytest.mark.verilog
def test_system_small_geometry(test_name):
    report = build_dir("system") / "small.json"
    p = system_params("test", report=str(report))
    cocotb_run.run(Projector(DMDS["test"], mac=MAC, ip=IP, port=PORT, mdio_cycles=(40, 10)),
                   toplevel="projector", module="sim.tb.system", key="test", params=p)
    frames = json.loads(report.read_text())["frames"]
    assert len(frames) == 1 and all(f["max_error_lsb"] == 0 for f in frames)
