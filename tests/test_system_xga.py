"""The projector's core on full XGA (DLP7000, TI timing, DCLK 400 MHz), end to end on its
generated Verilog: two frames of the default scene over GMII (the second as a delta of the first),
stored as a sequence, one triggered
when the sequencer is ready, then two triggered faster than frames can be shown (held, played
back to back at the frame starts of the schedule model), every DLPC410 rule checked on the
recorded pins, the image the camera sees exact. Shares its Verilator build with ``make sim``."""

import pytest

from sim import xga


@pytest.mark.verilog
def test_xga_frames_end_to_end():
    r = xga.run("test", frames=2, one_by_one=1, back_to_back=2)
    assert r["dclk_hz"] == 400e6
    shown = r["frames"]
    assert len(shown) == 3
    for frame in shown:
        assert frame["max_error_lsb"] == 0, f"{frame['wrong_pixels']} pixels wrong"
        assert frame["span_cycles"] == r["model_span_cycles"], "the frame's pulses are the schedule model's"
    assert shown[0]["latency_cycles"] <= 8, "a trigger becomes a clocking pulse within a few cycles"
    # held triggers: the frames follow one another at the gateware's own pace (xga.run checks
    # the frame starts against the schedule model's), the shortest trigger-to-trigger period
    (period,) = r["periods_measured"]
    assert abs(period - r["period_cycles"]) <= 2, (period, r["period_cycles"])
    status = r["status"]
    rows = xga.DMD.rows
    # the first frame whole, the second as a delta of it (the rows the target changed)
    (delta_rows,) = r["scene"]["delta_rows"]
    assert status["rows"] == rows + delta_rows and 0 < delta_rows < rows // 4
    assert status["store_frames_complete"] == 2 and status["store_rows_refused"] == 0
    # every datagram reached the stack; the one per frame to another UDP port was dropped and counted
    assert status["frames"] == status["records_image"] + 2 + 2
    assert status["drop_udp_port"] == 2
    assert status["accepted"] == status["records_image"] + 2     # the control record, the status query
    drops = {k: v for k, v in status.items() if k.startswith("drop") and k != "drop_udp_port" and v}
    assert not drops, drops
    assert status["triggers"] == 3 and status["trigger_overruns"] == 0 and status["triggers_held"] == 1
    # the sequence of two frames plays on: the last frame shown is the first again
    assert status["shown_frame"] == (len(shown) - 1) % 2 and status["newest_frame"] == 1
    assert status["rows_incomplete"] == 0
