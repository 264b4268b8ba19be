"""The projector's core on full XGA (DLP7000, TI timing), end to end on its generated Verilog:
one frame of the default scene over GMII, triggered, every DLPC410 rule checked on the recorded
pins, the image the camera sees exact. Shares its Verilator build with ``make sim``."""

import pytest

from sim import xga


@pytest.mark.verilog
def test_xga_frame_end_to_end():
    r = xga.run("test", frames=1)
    (frame,) = r["frames"]
    assert frame["max_error_lsb"] == 0, f"{frame['wrong_pixels']} pixels wrong"
    assert frame["latency_cycles"] <= 8, "a trigger becomes a clocking pulse within a few cycles"
    assert frame["span_cycles"] == r["model_span_cycles"], "the frame's pulses are the schedule model's"
    status = r["status"]
    rows = xga.DMD.rows
    assert status["rows"] == rows and status["last_row"] == rows - 1
    # every datagram reached the stack; the one to another UDP port was dropped and counted
    assert status["frames"] == status["records_image"] + 2
    assert status["drop_udp_port"] == 1
    assert status["accepted"] == status["records_image"] + 1     # plus the status query
    drops = {k: v for k, v in status.items() if k.startswith("drop") and k != "drop_udp_port" and v}
    assert not drops, drops
    assert status["triggers"] == 1 and status["trigger_overruns"] == 0
    assert status["shown_frame"] == 0 and status["newest_frame"] == 0 and status["rows_incomplete"] == 0
