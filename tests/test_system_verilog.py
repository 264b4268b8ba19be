"""The projector's core end to end on its generated Verilog: configured, armed and fed over GMII,
the DLPC410 model out, the status reply read back; faults interleaved (the testbench:
:mod:`sim.tb.system_tb`)."""

import pytest

from sim.rigs import system_run as system


@pytest.mark.verilog
def test_system_small_geometry():
    report = system.run("test")
    frames = report["frames"]
    n = system.PARAMS["frames"]
    # the scene streamed, then: a trigger burst (frame n), a new register set (frame n + 1), a
    # frame with a lost record (never shown: frame n + 1 again), a whole frame after it; the
    # DDR2 lost while it plays again (not checked: cut), then it shown dark, and a new frame; a
    # key frame, two deltas of it, and the second again (a delta whose base is gone is refused)
    assert [f["index"] for f in frames] == [*range(n), n, n + 1, n + 1, n + 3, n + 3, n + 4,
                                            n + 5, n + 6, n + 7, n + 7]
    assert [f["dark"] for f in frames] == [False] * (n + 4) + [True] + [False] * 5
    assert all(f["max_error_lsb"] == 0 for f in frames)
    # a trigger becomes a clocking pulse within a few cycles
    assert all(f["latency_cycles"] <= 8 for f in frames)
    status = report["status"]      # the testbench checked every counter; the headline ones here
    assert status["triggers"] == status["frames_shown"] == len(frames) + 1       # the frame cut
    assert status["store_calibration_losses"] == 1
    assert status["store_rows_no_base"] == report["rows_no_base"] > 0
    # the frame shown last, by its id, and the newest id handed on (the delta refused after it)
    assert status["shown_frame"] == frames[-1]["index"] == status["newest_frame"] - 1
    # the lost record's neighbours: the row the record before it began, the row the one after it ends
    assert status["rows_incomplete"] == 2
    assert status["trigger_overruns"] == 3 and status["registers_applied"] == 2
    assert status["store_frames_abandoned"] == 1
    # bad frames interleaved with each of the scene's frames and the first fault frame
    assert status["mac_bad_fcs"] == status["drop_udp_port"] == n + 1
    assert status["drop_app_value"] == 5 * (n + 1) and status["drop_app_length"] == n + 1
    assert status["records_sequencer"] == 2 and status["records_control"] == 2


@pytest.mark.verilog
def test_system_sequence_entries():
    """A sequence played by its entry table, end to end: configured over GMII, every pixel's
    light each entry's frame at its own exposure and planes, a trigger after the last entry
    ignored and counted (``sim/tb/system_tb.py``, ``sequence_entries_play_as_their_table_says``)."""
    report = system.run("test", testcase="sequence_entries_play_as_their_table_says")
    assert report["latency_cycles"] <= 8
    assert report["status"]["triggers_after_end"] == 1


@pytest.mark.verilog
def test_system_tiled_board_clock_loop():
    """The clock loop inside the core, configured over GMII: it runs in SYNC mode with the
    master's period, a pulse left out is a slip in the status reply, and it is off in another
    mode (``sim/tb/system_tb.py``, ``a_tiled_board_trims_its_clock``)."""
    report = system.run("test", testcase="a_tiled_board_trims_its_clock")
    assert report["status"]["clock_loop_slips"] == 1
    assert len(report["trims"]) == 12 and all(report["trims"][1:])

