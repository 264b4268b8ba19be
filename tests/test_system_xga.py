"""The projector's core on full XGA (DLP7000, TI timing, DCLK 400 MHz), end to end on its
generated Verilog: two frames of the default scene over GMII (the second as a delta of the first),
stored as a sequence played by an entry table (the second frame, then the first twice), then
three triggers faster than frames can be shown: the first finds the sequencer ready, the others
are held and played back to back at the frame starts of the schedule model; every DLPC410 rule
checked on the recorded pins, the image the camera sees exact. Shares its Verilator build with
``make sim`` (:func:`sim.rigs.xga_run.run`; the testbench :mod:`sim.tb.fast_system_rig_tb`)."""

import pytest

from sim.rigs import gated_run
from sim.rigs import xga_run as xga


@pytest.mark.verilog
def test_xga_frames_end_to_end():
    entries = (1, 0, 0)
    r = xga.run("test", frames=2, one_by_one=0, back_to_back=3, entries=entries)
    assert r["dclk_hz"] == 400e6
    shown = r["frames"]
    assert len(shown) == 3
    # each frame is the image of its entry's slot, exact (the two frames differ where the target moved)
    for frame in shown:
        assert frame["max_error_lsb"] == 0, f"{frame['wrong_pixels']} pixels wrong"
        assert frame["span_cycles"] == r["model_span_cycles"], "the frame's pulses are the schedule model's"
    assert shown[0]["latency_cycles"] <= 8, "a trigger becomes a clocking pulse within a few cycles"
    # held triggers: the frames follow one another at the gateware's own pace (xga.run checks
    # the frame starts against the schedule model's), a frame period apart
    periods = r["periods_measured"]
    assert len(periods) == 2 and all(abs(period - r["period_cycles"]) <= 2 for period in periods), periods
    status = r["status"]
    rows = xga.DMD.rows
    # the first frame whole, the second as a delta of it (the rows the target changed)
    (delta_rows,) = r["scene"]["delta_rows"]
    assert status["rows"] == rows + delta_rows and 0 < delta_rows < rows // 4
    assert status["store_frames_complete"] == 2 and status["store_rows_refused"] == 0
    # every datagram reached the stack; the one per frame to another UDP port was dropped and counted
    setup = 2 + len(entries)           # two control records and the entries
    assert status["frames"] == status["records_image"] + setup + 2 + 1
    assert status["drop_udp_port"] == 2
    assert status["accepted"] == status["records_image"] + setup + 1     # and the status query
    assert status["records_entry"] == len(entries) and status["sequence_entries_skipped"] == 0
    drops = {k: v for k, v in status.items() if k.startswith("drop") and k != "drop_udp_port" and v}
    assert not drops, drops
    assert status["triggers"] == 3 and status["trigger_overruns"] == 0 and status["triggers_held"] == 2
    # the last entry shows slot 0 (each frame's image was checked against its entry's slot above)
    assert status["shown_frame"] == 0 and status["newest_frame"] == 1
    assert status["rows_incomplete"] == 0


def _records(path):
    """The UDP payloads of a GMII replay file (read back from its bytes: preamble and FCS cut)
    with their destination ports."""
    from scapy.layers.inet import UDP
    from scapy.layers.l2 import Ether

    data = path.read_bytes()
    frames, frame = [], bytearray()
    for k in range(0, len(data), 2):
        if data[k] & 1:
            frame.append(data[k + 1])
        elif frame:
            frames.append(bytes(frame[8:-4]))
            frame = bytearray()
    udp = [Ether(f)[UDP] for f in frames]
    return [(u.dport, bytes(u.payload)[:u.len - 8]) for u in udp]      # (short frames are padded)


def test_window_holds_back_the_first_frames_last_datagram(tmp_path):
    """``make sim WINDOW=1``'s stimulus: every frame whole, the first one last, its last record in
    a replay of its own; every record numbered in the order it is sent, and the first frame's
    records, held one included, exactly the host encoder's."""
    from pathlib import Path

    import numpy as np

    from host import codec
    from sim.rigs.scene import default_scene

    images = default_scene(3, 96, 128)
    sends, held, query, _ = xga._replay_files(tmp_path, images, hold_last=True)
    assert [s["kind"] for s in sends] == ["control", "whole", "whole", "whole"]
    assert [s["what"].split(":")[0] for s in sends[1:]] == ["frame 2/3", "frame 3/3", "frame 1/3"]
    assert held["kind"] == "held"
    sent = [r for s in [*sends, held, {"path": query}] for r in _records(Path(s["path"]))]
    ours = [payload for port, payload in sent if port == xga.PORT]
    numbers = [codec.decode(payload)[0]["sequence"] for payload in ours]
    assert numbers == [k % 256 for k in range(len(ours))]
    first = [payload for port, payload in _records(Path(sends[3]["path"])) if port == xga.PORT]
    (last,) = [payload for _, payload in _records(Path(held["path"]))]
    expect = codec.image_records(images[0], frame=0, sequence=codec.decode(first[0])[0]["sequence"])
    assert [*first, last] == [bytes(r) for r in expect]
    # the normal run: the first frame whole and first, the others as deltas of it
    sends, held, _, _ = xga._replay_files(tmp_path, images)
    assert held is None and [s["kind"] for s in sends] == ["control", "whole", "delta", "delta"]
    assert np.any(images[1] != images[0])


@pytest.mark.verilog
def test_binary_patterns_from_the_store_while_gige_writes():
    """1-bit patterns chained from the store on the full DLP7000 at DCLK 400 MHz, set over GMII
    (a bit depth of 1, the binary plan's registers), while the next frame is written at line
    rate: every pattern is one of the frames sent, exact, in order (``xga.binary_stream`` raises
    otherwise), and every pattern period is the plan's: the memory model keeps the rows' pace
    under the writes."""
    r = xga.binary_stream("test-binary", frames=2, log=lambda _text: None)
    assert r["frames_shown"][0] == 0 and r["frames_shown"][-1] == 1
    assert len(r["periods_during_ingest"]) > 50
    assert set(r["periods"]) == {r["period_cycles"]}, sorted(set(r["periods"]))
    assert r["status"]["pulses_late"] == 0 and r["status"]["store_frames_complete"] == 2


@pytest.mark.verilog
def test_gated_frames_from_the_store_while_gige_writes():
    """Gated 8-bit frames chained from the store on the full DLP7000 at DCLK 400 MHz, set over
    GMII (the gated plan's registers), while the next frame is written at line rate: every frame
    between two others is one of the frames sent within half an LSB under the camera model with
    the gate pin, in order (``gated_run.gated_stream`` raises otherwise), and every frame period
    is the plan's: the memory model keeps the rows' pace under the writes."""
    r = gated_run.gated_stream("test-gated", frames=2, tail_us=1200, log=lambda _text: None)
    assert r["frames_shown"][0] == 0 and r["frames_shown"][-1] == 1
    assert len(r["periods_during_ingest"]) >= 5
    assert set(r["periods"]) == {r["period_cycles"]}, sorted(set(r["periods"]))
    assert r["error_lsb_max"] <= 0.5 and r["status"]["pulses_late"] == 0
