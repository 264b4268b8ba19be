"""The projector's core end to end on its generated Verilog: GMII in, DLPC410 model out."""

import pytest

from sim import system


@pytest.mark.verilog
def test_system_small_geometry():
    report = system.run("test")
    frames = report["frames"]
    assert len(frames) == system.PARAMS["frames"]
    assert all(f["max_error_lsb"] == 0 for f in frames)
    # a trigger becomes a clocking pulse within a few cycles
    assert all(f["latency_cycles"] <= 8 for f in frames)
