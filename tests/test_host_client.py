"""The host client and CLI against an in-process UDP server on 127.0.0.1 that plays projector
with the reference models: the endpoint's (records, rows, counters) and the store's frame-slot
policy (which frames it takes, which rows it refuses, which whole frame a delta frame takes its
other rows from); a software trigger shows the newest complete frame.

The sync master's client and ``python -m host master`` against one that plays sync master as
``docs/protocol.md`` describes it; its record bytes are checked against encodings written out
here with :mod:`struct`."""

import dataclasses
import socket
import struct
import threading

import numpy as np
import pytest

from host import Client, ClientError, MasterClient, cli, codec, levels
from sim.models.net_model import Model
from sim.models.slots_model import SlotPolicy
from spec import records
from spec.facts import DMDS, TEST_DMD
from spec.registers import MAX_GROUPS, MIN_CHAINED, PlaneOrder, ResetMode, TriggerMode

DLP7000 = DMDS["dlp7000"]

#: The store's refusals, summed into the status reply's ``store_rows_refused``.
REFUSALS = ("rows_outside", "rows_stale", "rows_shown", "rows_duplicate", "rows_no_slot", "rows_no_base")
SHAPE = (TEST_DMD.rows, TEST_DMD.columns)
#: The common header: magic "DM", version, type, sequence.
HEADER = ">HBBB"
#: A sync master's MASTER_CONFIG fields in ``apply`` bit order, as the protocol page lists them.
NAMES = ("mode", "armed", "period", "min_period", "width")
STATUS_QUERY, MASTER_CONTROL, MASTER_STATUS = 3, 8, 9


class LoopbackDevice:
    """A device on a UDP socket of 127.0.0.1 (``port``), served by a thread once started: each
    datagram is kept in ``received`` and handed to :meth:`take`, whose answer (bytes; None for
    none) goes back to its sender."""

    def __init__(self):
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.bind(("127.0.0.1", 0))
        self.sock.settimeout(0.05)
        self.port = self.sock.getsockname()[1]
        self.received = []
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._serve, daemon=True)

    def start(self):
        self._thread.start()
        return self

    def _serve(self):
        while not self._stop.is_set():
            try:
                raw, sender = self.sock.recvfrom(65536)
            except socket.timeout:
                continue
            self.received.append(raw)
            reply = self.take(raw)
            if reply is not None:
                self.sock.sendto(reply, sender)

    def take(self, raw):
        raise NotImplementedError

    def close(self):
        self._stop.set()
        self._thread.join()
        self.sock.close()


class FakeProjector(LoopbackDevice):
    """Decodes every datagram with the reference model, stores its rows with the store's policy;
    answers status queries (or, with ``mode``, answers badly or not at all)."""

    def __init__(self, mode="good"):
        super().__init__()
        self.model = Model(TEST_DMD, 0x020000000001, 0x7F000001, self.port, frame_bits=16)
        self.store = SlotPolicy(TEST_DMD.rows, slots=4)
        self.shown = None
        self.depths = []            # bit depth of each frame the store completed
        self.kinds = {}             # frame id -> (base, carried) of its image records
        self.stored = {}            # (frame id, row) -> the row's bytes the store took
        self.mode = mode
        self.status_values = {}     # status fields the test sets

    def take(self, raw):
        replies_before, rows_before = len(self.model.replies), len(self.model.rows)
        if self.model.record(raw) == "image":
            body = codec.decode(raw)[1]
            self.kinds[body["frame"]] = (body.get("base", 0), body.get("carried", 0))
        for frame, row, data in self.model.rows[rows_before:]:
            complete = self.store.counters["frames_complete"]
            base, carried = self.kinds[frame]
            # a whole frame's row is the policy's row(frame, row, depth) with base and carried at their defaults
            delta = {"base": base, "carried": carried} if carried else {}
            if self.store.row(frame, row, self.model.config["bit_depth"], **delta):
                self.stored[frame, row] = data
            if self.store.counters["frames_complete"] > complete:
                self.depths.append(self.store.frames[frame]["depth"])
        if self.model.triggers and self.store.can_answer():
            self.model.triggers = 0
            if self.shown is not None:
                self.store.release(self.shown)
            self.shown = self.store.ask()
        if len(self.model.replies) == replies_before or self.mode == "silent":
            return None
        sequence = self.model.replies[-1][1]["sequence"]
        values = {name: self.model.counters.get(name, 0) for name, _ in records.STATUS_REPLY}
        values["store_rows_refused"] = sum(self.store.counters.get(name, 0) for name in REFUSALS)
        values["store_rows_no_base"] = self.store.counters.get("rows_no_base", 0)
        values["shown_frame"] = self.shown or 0
        values.update(self.status_values)
        reply = codec.status_reply(sequence, values)
        return reply[:20] if self.mode == "garbled" else reply

    def image(self, frame):
        """The image frame ``frame`` shows: its own rows, and its base's where a delta carries none."""
        base, carried = self.kinds[frame]
        rows = [self.stored[frame if (frame, row) in self.stored or not carried else base, row]
                for row in range(TEST_DMD.rows)]
        return np.frombuffer(b"".join(rows), np.uint8).reshape(SHAPE)


@pytest.fixture
def projector(request):
    server = FakeProjector(getattr(request, "param", "good")).start()
    yield server
    server.close()


def test_send_image_and_status(projector):
    image = np.random.default_rng(1).integers(0, 256, (TEST_DMD.rows, TEST_DMD.columns), dtype=np.uint8)
    with Client("127.0.0.1", projector.port, timeout=1.0, rate=50e6, mtu=1500) as client:
        sent = client.send_image(image, frame=3)
        client.control(armed=1, software_trigger=True)
        status = client.status()
    # 12,288 pixels in records of 1,462 (a 1500-byte MTU): 9 records, rows split between them
    assert (sent.frame, sent.depth, sent.records, sent.error_lsb) == (3, 8, 9, 0.0)
    assert status["records_image"] == 9 and status["records_control"] == 2   # the depth, then arming
    assert status["rows"] == TEST_DMD.rows and status["sequence_gaps"] == 0 and status["rows_incomplete"] == 0
    rows = {row: data for _tag, row, data in projector.model.rows}
    assert all(rows[r] == image[r].tobytes() for r in range(TEST_DMD.rows))
    assert projector.model.config["armed"] == 1 and status["shown_frame"] == 3
    assert all(len(raw) <= 1472 for raw in projector.received)


def test_records_fill_the_path_mtu(projector):
    """Without an MTU given, the client takes the path's (loopback: more than the projector's
    9,000-byte limit, so jumbo records); given one, it fills that."""
    image = np.zeros((TEST_DMD.rows, TEST_DMD.columns), np.uint8)
    with Client("127.0.0.1", projector.port) as client:
        assert client.mtu >= 9000 and client.limit == records.MAX_RECORD
        client.send_image(image)
    with Client("127.0.0.1", projector.port, mtu=2000) as client:
        client.send_image(image)
    sizes = [len(raw) for raw in projector.received if raw[3] == records.RecordType.IMAGE]
    # 12,288 pixels: 8,962 + 3,326 in jumbo records, 6 x 1,962 + 516 in records for a 2,000-byte MTU,
    # each with its 10-byte header
    assert sizes == [8972, 3336] + [1972] * 6 + [526]


def test_a_record_too_large_for_the_path_is_a_clear_error(projector):
    """The don't-fragment flag is set: a record larger than the path allows is refused by the
    system, and the client says what to do."""
    with Client("127.0.0.1", projector.port, check=False) as client:
        with pytest.raises(ClientError, match="a 65600-byte record does not fit the path .* give mtu="):
            client.send_records([codec.image_record(1, 0, bytes(65590))])


def test_frame_ids_continue_after_the_projectors_newest(projector):
    """A sender that restarts continues after the newest frame id the projector has: its frames
    are taken. One that starts again from an id the projector holds is refused, and the client
    says so."""
    image = np.full((TEST_DMD.rows, TEST_DMD.columns), 200, np.uint8)
    with Client("127.0.0.1", projector.port) as client:
        first = [client.send_image(image).frame for _ in range(3)]
    with Client("127.0.0.1", projector.port) as client:
        again = client.send_image(image).frame
        with pytest.raises(ClientError, match=r"store_rows_refused \+96: .* newest frame id is 4"):
            client.send_image(image, frame=first[0])
    assert first == [1, 2, 3] and again == 4
    assert projector.store.counters["rows_stale"] == TEST_DMD.rows and projector.store.counters["frames_complete"] == 4


def test_depth_per_frame_and_rounding(projector):
    """Each frame at the smallest depth that shows it within the tolerance: a control record
    sets the depth when it changes, and the store keeps the frame at that depth."""
    shape = (TEST_DMD.rows, TEST_DMD.columns)
    binary = np.where(np.indices(shape).sum(axis=0) % 2, 255, 0).astype(np.uint8)
    grey = np.random.default_rng(3).integers(0, 256, shape, dtype=np.uint8)
    dim = np.zeros(shape)
    dim[10:20, 10:20] = 15.0                                # a dim target on black
    with Client("127.0.0.1", projector.port) as client:
        sent = [client.send_image(binary), client.send_image(grey), client.send_image(binary),
                client.send_image(dim, depth=4), client.send_image(dim, tolerance=1.0)]
    assert [s.depth for s in sent] == [1, 8, 1, 4, 7] == projector.depths
    assert [s.error_lsb for s in sent[:3]] == [0.0, 0.0, 0.0]
    assert sent[3].error_lsb == pytest.approx(2.0) and sent[4].error_lsb == pytest.approx(15 - 255 * 7 / 127)
    assert projector.model.counters["records_control"] == 5
    # the dim target at depth 4 is level 1 (17 LSB), not black
    rows = {row: data for _tag, row, data in projector.model.rows[-2 * TEST_DMD.rows:-TEST_DMD.rows]}
    assert rows[15][15] >> 4 == 1 == levels.levels(15, 4)


def _target(row, column, level=255, background=None):
    """An 8 x 8 target at ``row``, ``column`` on a background (default: black)."""
    image = np.zeros(SHAPE, np.uint8) if background is None else background.copy()
    image[row:row + 8, column:column + 8] = level
    return image


def test_a_scene_streams_as_deltas_of_its_key_frame(projector):
    """With ``delta``, each image goes as a delta frame of the last whole frame (the key) when at
    most that fraction of its rows changed and the key's depth shows it; else whole, as the new
    key. The projector shows each frame as sent: a delta's rows, its key's elsewhere, at the key's
    depth."""
    noise = np.where(np.random.default_rng(4).random(SHAPE) < 0.5, 255, 0).astype(np.uint8)
    band = np.zeros(SHAPE, np.uint8)
    band[20:28] = 36                              # 36 LSB: depth 3 shows it, within half an LSB
    steps = [   # image; then what goes: the index of its base (None: whole), rows carried, depth
        (_target(10, 10), None, 96, 1),           # the first frame is whole: the key
        (_target(10, 14), 0, 8, 1),               # the target moves: its 8 rows
        (_target(13, 14), 0, 11, 1),              # rows 10 to 20 differ from the key's
        (_target(10, 10), 0, 1, 1),               # the key again: a delta carries a row at least
        (noise, None, 96, 1),                     # more than half the rows changed: whole
        (_target(40, 40, 103, noise), None, 96, 8),   # a grey target needs depth 8: whole
        (_target(44, 40, 103, noise), 5, 8, 8),       # 4 rows down: rows 40 to 43 and 48 to 51
        (_target(40, 40, 255, noise), 5, 8, 8),       # white on white: depth 1 would do, the key's 8 shows it
        (band, None, 96, 3),
        (np.where(band, 85, 0).astype(np.uint8), None, 96, 2),  # 85 needs depth 2; depth 3 shows it 12 LSB off
    ]
    with Client("127.0.0.1", projector.port) as client:
        client.control(armed=1)
        sent = []
        for image, *_ in steps:
            sent.append(client.send_image(image, delta=0.5))
            client.control(software_trigger=True)
            assert client.status()["shown_frame"] == sent[-1].frame
            assert (projector.image(sent[-1].frame) == levels.quantise(image, sent[-1].depth).data).all()
        status = client.status()
    frames = [s.frame for s in sent]
    assert [(None if s.base is None else frames.index(s.base), s.rows, s.depth) for s in sent] == \
        [tuple(step[1:]) for step in steps]
    assert [projector.kinds[s.frame] for s in sent] == [(s.base or 0, s.rows if s.delta else 0) for s in sent]
    assert projector.depths == [s.depth for s in sent]
    assert status["rows"] == sum(s.rows for s in sent) and status["store_rows_refused"] == 0
    assert [s.error_lsb for s in sent] == [0.0] * 8 + [pytest.approx(255 * 1 / 7 - 36), 0.0]


def test_a_delta_whose_base_is_gone_goes_whole(projector):
    """Another sender's whole frame replaces the delta that kept the key frame: the projector no
    longer holds it and refuses the next delta of it (``store_rows_no_base``); the client sends
    that image again as a whole frame, the new key, and says why."""
    with Client("127.0.0.1", projector.port) as first, Client("127.0.0.1", projector.port) as other:
        key = first.send_image(_target(10, 10), delta=0.5)
        moved = first.send_image(_target(10, 14), delta=0.5)
        intruder = other.send_image(np.full(SHAPE, 255, np.uint8))
        again = first.send_image(_target(10, 18), frame=intruder.frame + 1, delta=0.5)
        after = first.send_image(_target(10, 22), delta=0.5)
    assert moved.base == key.frame and not intruder.delta
    assert (again.delta, again.frame, again.rows) == (False, intruder.frame + 2, TEST_DMD.rows)
    assert again.refused.startswith(f"frame {intruder.frame + 1}: the projector took ")
    assert ("store_rows_no_base +8: the projector no longer holds the whole frame a delta is based on "
            "(send a whole frame") in again.refused
    assert (after.base, after.rows) == (again.frame, 8)
    assert projector.store.counters["rows_no_base"] == 8


def test_an_image_of_another_size_is_refused(projector):
    with Client("127.0.0.1", projector.port) as client:
        with pytest.raises(ClientError, match="the image is 64x96, the projector's DMD 128x96"):
            client.send_image(np.zeros((96, 64), np.uint8))


@pytest.mark.parametrize("projector", ["silent"], indirect=True)
def test_status_timeout_is_a_clear_error(projector):
    with Client("127.0.0.1", projector.port, timeout=0.1) as client:
        with pytest.raises(ClientError, match="no status reply from 127.0.0.1.*after 2 tries"):
            client.status(retries=1)


@pytest.mark.parametrize("projector", ["garbled"], indirect=True)
def test_garbled_reply_is_a_clear_error(projector):
    with Client("127.0.0.1", projector.port, timeout=0.5) as client:
        with pytest.raises(ClientError, match="bad status reply"):
            client.status()


def test_pacing_limits_the_rate(projector):
    import time
    image = np.zeros((TEST_DMD.rows, TEST_DMD.columns), np.uint8)
    with Client("127.0.0.1", projector.port, rate=200e3, check=False) as client:
        client.next_frame()
        start = time.monotonic()
        client.send_sequence([image] * 3)
        elapsed = time.monotonic() - start
    # 3 jumbo records a frame, 37 kB in all: the last one may leave at 31 kB / 200 kB/s
    assert elapsed >= 0.1


def test_cli_send_and_status(projector, tmp_path, capsys):
    path = tmp_path / "scene.npy"
    np.save(path, np.full((TEST_DMD.rows, TEST_DMD.columns), 9, np.uint8))
    base = ["--address", "127.0.0.1", "--port", str(projector.port)]
    assert cli.main(base + ["send", str(path), "--frame", "2", "--mtu", "1500"]) == 0
    out = capsys.readouterr().out
    assert f"frame 2: {path}, 8-bit, 9 records, rounding error 0 LSB" in out
    assert "sent 1 frame(s) in 9 records of at most 1472 bytes (MTU 1500)" in out
    assert cli.main(base + ["send", str(path), str(path)]) == 0
    assert "frame 3:" in (out := capsys.readouterr().out) and "frame 4:" in out
    assert cli.main(base + ["status"]) == 0
    assert "records_image" in capsys.readouterr().out
    assert cli.main(base + ["send", str(tmp_path / "missing.npy")]) == 1
    assert "error: cannot read" in capsys.readouterr().err


def test_cli_send_deltas(projector, tmp_path, capsys):
    paths = [tmp_path / f"scene{i}.npy" for i in range(3)]
    for path, image in zip(paths, [_target(10, 10), _target(10, 14), np.full(SHAPE, 255, np.uint8)], strict=True):
        np.save(path, image)
    base = ["--address", "127.0.0.1", "--port", str(projector.port)]
    assert cli.main(base + ["send", "--delta", "0.5", "--frame", "7"] + [str(p) for p in paths]) == 0
    out = capsys.readouterr().out
    assert f"frame 7: {paths[0]}, 1-bit, 2 records, rounding error 0 LSB\n" in out
    assert f"frame 8: {paths[1]}, 1-bit, 1 records, rounding error 0 LSB, delta of frame 7 carrying 8 rows" in out
    assert f"frame 9: {paths[2]}, 1-bit, 2 records, rounding error 0 LSB\n" in out


def test_cli_reports_unreachable(capsys):
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.bind(("127.0.0.1", 0))
    port = sock.getsockname()[1]   # bound but never answers
    try:
        assert cli.main(["--address", "127.0.0.1", "--port", str(port), "--timeout", "0.05", "status"]) == 1
    finally:
        sock.close()
    assert "error: no status reply" in capsys.readouterr().err


def test_python_m_host_status(projector):
    """The command line as users run it, in a separate process."""
    import os
    import subprocess
    import sys
    from pathlib import Path
    root = Path(__file__).resolve().parents[1]
    env = {**os.environ, "PYTHONPATH": str(root)}
    done = subprocess.run([sys.executable, "-m", "host", "--address", "127.0.0.1", "--port",
                           str(projector.port), "status"], capture_output=True, text=True, env=env,
                          cwd=root, timeout=60)
    assert done.returncode == 0, done.stderr
    assert "records_status" in done.stdout


def test_cli_configure_says_the_rate_and_sends_the_plan(projector, capsys):
    """``configure`` plans with the schedule model, prints the rate it reaches, then sends the
    register set (checked and taken by the model as the projector takes it) and arms."""
    from spec import schedule
    plan = schedule.plan(TEST_DMD, 200e6, depth=6)
    base = ["--address", "127.0.0.1", "--port", str(projector.port)]
    # the projector here is built for DCLK 200 MHz (one beat a cycle); the default is 400 MHz
    assert cli.main(base + ["configure", "--dmd", "test", "--dclk", "200e6", "--depth", "6", "--dry-run"]) == 0
    out = capsys.readouterr().out
    assert f"{plan.rate_hz:.1f} frames/s ({plan.frame_cycles} cycles of 200 MHz per frame)" in out
    assert f"least significant plane {plan.params.lsb} cycles ({plan.params.lsb / 200:.2f} us)" in out
    # at 400 MHz the durations are still in 200 MHz cycles (a bug once halved the microseconds)
    assert cli.main(base + ["configure", "--dmd", "test_400", "--dclk", "400e6", "--depth", "6", "--dry-run"]) == 0
    p400 = schedule.plan(DMDS["test_400"], 400e6, depth=6).params
    assert f"least significant plane {p400.lsb} cycles ({p400.lsb / 200:.2f} us)" in capsys.readouterr().out
    assert projector.received == []
    assert cli.main(base + ["configure", "--dmd", "test", "--dclk", "200e6", "--depth", "6"]) == 0
    assert cli.main(base + ["arm"]) == 0
    assert cli.main(base + ["status"]) == 0
    model = projector.model
    assert model.counters["records_sequencer"] == 1 and model.counters["drop_app_value"] == 0
    assert model.registers == [records.register_wire(plan.params.registers(TEST_DMD))]
    assert model.config["bit_depth"] == 6 and model.config["armed"] == 1
    def configured(*options):
        """The register set the projector took from ``configure`` with ``options`` (a status
        round trip after it: the fake projector handles records in order, on its own thread)."""
        assert cli.main(base + ["configure", "--dmd", "test", "--dclk", "200e6", "--depth", "6", *options]) == 0
        assert cli.main(base + ["status"]) == 0
        return model.registers[-1]

    # the anchor register: the frame starts at that position of the order (a tiled display's pulse)
    taken = configured("--order", "LSB_FIRST", "--anchor", "5")
    assert taken["anchor"] == 5 and taken["order"] == PlaneOrder.LSB_FIRST
    # a tiled display's board: the sync master's period (in dmd cycles) turns its clock loop on
    taken = configured("--trigger", "sync", "--period", "0.0025")
    assert (taken["trigger"], taken["period"]) == (TriggerMode.SYNC, 500_000)
    assert configured("--trigger", "sync")["period"] == 0
    # the interleaved plane order (its table for 6 planes, the rest after it) and the loose
    # RST_ACTIVE reading, as the schedule model plans them
    taken = configured("--order", "INTERLEAVED", "--reset-mode", "SINGLE", "--rst-active", "loose")
    loose = schedule.plan(TEST_DMD, 200e6, depth=6, reset_mode=ResetMode.SINGLE, strict_rst=False,
                          order=PlaneOrder.TABLE, order_table=(5, 1, 4, 2, 3, 0, 6, 7)).params
    assert taken == records.register_wire(loose.registers(TEST_DMD))
    assert (taken["order"], taken["strict_rst"]) == (PlaneOrder.TABLE, 0)


def test_sequencer_record_refuses_what_the_projector_would_drop():
    from spec import schedule
    wire = records.register_wire(schedule.plan(TEST_DMD, 200e6).params.registers(TEST_DMD))
    codec.sequencer_record(wire, dmd=TEST_DMD)
    with pytest.raises(ValueError, match="lsb_even_nonzero"):
        codec.sequencer_record({**wire, "lsb": 3}, dmd=TEST_DMD)
    with pytest.raises(ValueError, match="lsb_keepable"):
        codec.sequencer_record({**wire, "lsb": 2}, dmd=TEST_DMD)
    # group g's offset is in bits 24g.. of the field: group 1 a row cycle after the first pulses
    # (a block clear on the DLP7000: 16 cycles), too close for a first pulse timed from them;
    # an odd offset
    groups = {**wire, "order": PlaneOrder.GROUPS.value}
    with pytest.raises(ValueError, match="group_offsets_keepable"):
        codec.sequencer_record({**groups, "group_offsets": 14 << 24}, dmd=DMDS["dlp7000"])
    assert not records.register_faults({**groups, "group_offsets": 16 << 24}, DLP7000)["group_offsets_keepable"]
    # group 0 starts the frame: no group's offset below its own; its own, if not 0, a clear's
    # row cycles at least too
    assert records.register_faults({**groups, "group_offsets": 16}, DLP7000)["group_offsets_keepable"]
    assert not records.register_faults({**groups, "group_offsets": sum(18 << 24 * g for g in range(MAX_GROUPS))},
                                       DLP7000)["group_offsets_keepable"]
    # (group 0's, not 0, a row under way and the bus's notice of the pulse at least: 16 + 2)
    assert records.register_faults({**groups, "group_offsets": sum(16 << 24 * g for g in range(MAX_GROUPS))},
                                   DLP7000)["group_offsets_keepable"]
    assert records.register_faults({**groups, "group_offsets": sum(14 << 24 * g for g in range(MAX_GROUPS))},
                                   DLP7000)["group_offsets_keepable"]
    # where a clear is shorter than MIN_CHAINED (2 cycles), an offset or a stagger of 2 is refused:
    # the sequencer's timed first pulse needs that much notice
    assert records.register_faults({**groups, "group_offsets": 2 << 24}, TEST_DMD)["group_offsets_keepable"]
    assert not records.register_faults({**groups, "group_offsets": MIN_CHAINED << 24},
                                       TEST_DMD)["group_offsets_keepable"]
    phased = {**wire, "reset_mode": ResetMode.DUAL.value}
    assert records.register_faults({**phased, "stagger": 2}, TEST_DMD)["stagger_keepable"]
    assert not records.register_faults({**phased, "stagger": MIN_CHAINED}, TEST_DMD)["stagger_keepable"]
    with pytest.raises(ValueError, match="group_offsets_even"):
        codec.sequencer_record({**groups, "group_offsets": 4001 << 24}, dmd=TEST_DMD)
    codec.sequencer_record({**groups, "group_offsets": 4000 << 24}, dmd=TEST_DMD)
    periodic = {**wire, "trigger": TriggerMode.PERIODIC.value}
    with pytest.raises(ValueError, match="period_keepable"):
        codec.sequencer_record({**periodic, "period": wire["lsb"] - 2}, dmd=TEST_DMD)
    codec.sequencer_record({**periodic, "period": wire["lsb"]}, dmd=TEST_DMD)
    head, body, rest = codec.decode(codec.sequencer_record(wire, 9))
    assert head["type"] == records.RecordType.SEQUENCER and body == wire and rest == b""


def test_order_tables_must_name_every_plane_once():
    """TABLE's order table, and in GROUPS every group's table (used by the reset mode or not),
    must name each exponent 0..7 once; 2,000 random tables against a sorted comparison."""
    from spec import schedule
    wire = records.register_wire(schedule.plan(TEST_DMD, 200e6).params.registers(TEST_DMD))
    rng = np.random.default_rng(5)

    def packed(tables):
        return sum(int(e) << 3 * (8 * t + j) for t, table in enumerate(tables) for j, e in enumerate(table))
    for _ in range(1000):
        table = rng.permutation(8) if rng.random() < 0.5 else rng.integers(0, 8, 8)
        bad = sorted(table) != list(range(8))
        faults = records.register_faults({**wire, "order": PlaneOrder.TABLE.value,
                                          "order_table": packed([table])}, DLP7000)
        assert faults["order_table_permutation"] == bad
        g = int(rng.integers(0, 16))
        tables = [range(8)] * 16
        tables[g] = table
        faults = records.register_faults({**wire, "order": PlaneOrder.GROUPS.value,
                                          "group_tables": packed(tables)}, DLP7000)
        assert faults["group_tables_permutation"] == bad
    # not checked in an order that does not read the table
    repeats = packed([(7, 6, 5, 4, 3, 2, 1, 1)])
    codec.sequencer_record({**wire, "order": PlaneOrder.MSB_FIRST.value, "order_table": repeats}, dmd=TEST_DMD)
    with pytest.raises(ValueError, match="order_table_permutation"):
        codec.sequencer_record({**wire, "order": PlaneOrder.TABLE.value, "order_table": repeats}, dmd=TEST_DMD)


def test_a_periodic_trigger_faster_than_the_plans_frames_is_refused(projector, capsys):
    """A period the projector would take (at least one plane) but every frame of the planned
    depth outlasts: ``configure`` refuses it with the plan's trigger period, before sending."""
    from spec import schedule
    plan = schedule.plan(TEST_DMD, 200e6, depth=6)
    base = ["--address", "127.0.0.1", "--port", str(projector.port), "configure", "--dmd", "test",
            "--dclk", "200e6", "--depth", "6", "--trigger", "periodic"]
    short = (plan.trigger_cycles - 1) / schedule.FABRIC_HZ
    assert cli.main(base + ["--period", repr(short)]) == 1
    assert f"trigger period of {plan.trigger_cycles} cycles" in capsys.readouterr().err
    assert projector.received == []
    assert cli.main(base + ["--period", repr(plan.trigger_cycles / schedule.FABRIC_HZ)]) == 0
    periodic = dataclasses.replace(plan, params=dataclasses.replace(
        plan.params, trigger=TriggerMode.PERIODIC, period=plan.trigger_cycles - 1))
    with Client("127.0.0.1", projector.port) as client, pytest.raises(ClientError, match="outlast"):
        client.configure(periodic, TEST_DMD)


def test_configure_plans_with_the_measured_rst_active(projector, capsys):
    """``--t-rst measured`` plans with the longest RST_ACTIVE the projector reports; before any
    pulse (0) it says to show a frame first."""
    from spec import schedule
    base = ["--address", "127.0.0.1", "--port", str(projector.port), "configure", "--dmd", "test",
            "--dclk", "200e6", "--t-rst", "measured", "--dry-run"]
    assert cli.main(base) == 1
    assert "show a frame first" in capsys.readouterr().err
    default = schedule.plan(TEST_DMD, 200e6)
    projector.status_values["rst_active_cycles_max"] = default.params.t_rst + 91
    assert cli.main(base) == 0
    longer = schedule.plan(TEST_DMD, 200e6, t_rst_cycles=default.params.t_rst + 91)
    # (the measured fall, the synchroniser's latency after it, rounded up to even)
    assert longer.params.t_rst == default.params.t_rst + 92 + schedule.FALL_LATENCY
    assert longer.params.lsb > default.params.lsb
    assert f"{longer.rate_hz:.1f} frames/s" in capsys.readouterr().out


def test_play_sequence_sends_the_table_then_the_frames(projector):
    """``play_sequence``: the sequence mode, each entry record (checked by the reference model as
    the projector checks it), the control record that plays them once, then the frames; entries
    the projector would drop, or skip for planes their frame is not sent with, are refused
    before anything is sent."""
    rng = np.random.default_rng(5)
    images = [rng.integers(0, 256, SHAPE, dtype=np.uint8) for _ in range(2)]
    entries = [{"slot": 1}, {"slot": 0, "lsb": 400, "follow": True, "camera": False},
               {"slot": 1, "dark": 90 * 2, "depth": 3}, {"slot": 0, "depth": 2, "skip": 3},
               {"slot": 1, "depth": 1, "skip": 7}]
    with Client("127.0.0.1", projector.port, timeout=1.0, rate=50e6, mtu=1500) as client:
        with pytest.raises(ClientError, match="outside the sequence"):
            client.play_sequence(images, [{"slot": 2}])
        # as many frames as the memory holds of the DMD (128 MiB of 8-plane frames), at most
        # the 256 slots an entry names
        held = min(256, 128 * 2**20 // (SHAPE[0] * SHAPE[1]))
        with pytest.raises(ClientError, match=f"2 to {held} frames"):
            client.play_sequence(images[:1] * (held + 1), [{"slot": 0}])
        with pytest.raises(ClientError, match="entry 0: .*lsb_even"):
            client.play_sequence(images, [{"slot": 0, "lsb": 3}])
        with pytest.raises(ClientError, match="entry 1: .*depth"):
            client.play_sequence(images, [{"slot": 0}, {"slot": 1, "depth": 9}])
        with pytest.raises(ClientError, match="entry 1: .*skip"):
            client.play_sequence(images, [{"slot": 0}, {"slot": 1, "depth": 1, "skip": 8}])
        with pytest.raises(ClientError, match="entry 0: .*8 bits a frame has"):
            client.play_sequence(images, [{"slot": 0, "depth": 2, "skip": 7}])
        # at 4 bits a frame keeps bits 4..7: bit 3 is not in it, nor anything below 4 planes
        with pytest.raises(ClientError, match="entry 0: .*4-bit frame has; the projector would skip"):
            client.play_sequence(images, [{"slot": 0, "depth": 1, "skip": 4}], depth=4)
        with pytest.raises(ClientError, match="entry 1: skip 4 leaves no plane of its 4-bit frame"):
            client.play_sequence(images, [{"slot": 0, "skip": 3}, {"slot": 1, "skip": 4}], depth=4)
        assert projector.received == []
        assert client.sequence_frames() == held        # (from a status reply)
        first = len(projector.received)
        sent = client.play_sequence(images, entries, loop=False, depth=8)
    model = projector.model
    assert [(e["slot"], e["lsb"], e["dark"], e["follow"], e["camera_off"], e["depth"], e["skip"])
            for e in model.entries] == \
        [(1, 0, 0, 0, 0, 0, 0), (0, 400, 0, 1, 1, 0, 0), (1, 0, 180, 0, 0, 3, 0), (0, 0, 0, 0, 0, 2, 3),
         (1, 0, 0, 0, 0, 1, 7)]
    assert model.counters["records_entry"] == 5 and model.counters["drop_app_value"] == 0
    assert model.config["sequence_length"] == 2 and model.config["entries"] == 5 and model.config["loop"] == 0
    assert model.sequence_starts == 1
    kinds = [raw[3] for raw in projector.received[first:]]
    assert kinds[:7] == [records.RecordType.CONTROL] + [records.RecordType.ENTRY] * 5 + [records.RecordType.CONTROL]
    assert records.RecordType.IMAGE not in kinds[:7] and records.RecordType.IMAGE in kinds[7:]
    assert [s.frame for s in sent] == [0, 1]


def test_cli_sequence_plays_an_entry_table(projector, tmp_path):
    """``python -m host sequence``: the images stored as a sequence, the entries file's table
    played once."""
    rng = np.random.default_rng(9)
    paths = []
    for k in range(2):
        paths.append(tmp_path / f"frame{k}.npy")
        np.save(paths[-1], rng.integers(0, 256, SHAPE, dtype=np.uint8))
    table = tmp_path / "entries.json"
    table.write_text('[{"slot": 1}, {"slot": 0, "lsb": 600, "follow": true}]')
    base = ["--address", "127.0.0.1", "--port", str(projector.port)]
    assert cli.main(base + ["sequence", *map(str, paths), "--entries", str(table), "--once", "--depth", "8"]) == 0
    model = projector.model
    assert [(e["slot"], e["lsb"], e["follow"]) for e in model.entries] == [(1, 0, 0), (0, 600, 1)]
    assert model.config["entries"] == 2 and model.config["loop"] == 0 and model.sequence_starts == 1
    # an entry the projector would drop: refused before anything is sent
    sent = len(projector.received)
    table.write_text('[{"slot": 0, "dark": 5}]')
    assert cli.main(base + ["sequence", *map(str, paths), "--entries", str(table)]) == 1
    assert len(projector.received) == sent


# -- a tiled display's sync master ------------------------------------------------------------

def control_bytes(sequence, apply, action, mode=0, armed=0, period=0, min_period=0, width=0):
    """A master control record (21 bytes), field by field."""
    return (struct.pack(HEADER + "BBBB", 0x444D, records.VERSION, MASTER_CONTROL, sequence, apply, action, mode, armed)
            + period.to_bytes(5, "big") + min_period.to_bytes(5, "big") + struct.pack(">H", width))


class FakeMaster(LoopbackDevice):
    """A tiled display's sync master as ``docs/protocol.md`` describes it: checks each record in
    its order (magic, version, type, length, the configuration it would leave in force), drops
    and counts the first failure; applies a valid control record's fields and then its software
    trigger (a pulse in mode SOFTWARE, armed); answers a status query with a master status
    reply. Reads the records with :mod:`struct`, not the codec."""

    CLOCK_HZ = 125_000_000

    def __init__(self):
        super().__init__()
        self.config = {"mode": 0, "armed": 0, "period": 0, "min_period": 125_000, "width": 125}
        self.counters = {name: 0 for name, _ in records.MASTER_RECORD_COUNTERS} | {"pulses": 0}
        self._previous = None          # the last valid record's sequence number

    def kinds(self):
        return [raw[3] for raw in self.received]

    def _drop(self, counter):
        self.counters[counter] += 1

    def take(self, raw):
        if len(raw) < 5 or struct.unpack_from(">H", raw)[0] != 0x444D:
            return self._drop("drop_app_magic")
        _magic, version, kind, sequence = struct.unpack_from(HEADER, raw)
        if version != records.VERSION:
            return self._drop("drop_app_version")
        if kind not in (STATUS_QUERY, MASTER_CONTROL):
            return self._drop("drop_app_type")
        if len(raw) != {STATUS_QUERY: 5, MASTER_CONTROL: 21}[kind]:
            return self._drop("drop_app_length")
        if kind == MASTER_CONTROL:
            apply, action, mode, armed = raw[5:9]
            fields = {"mode": mode, "armed": armed, "period": int.from_bytes(raw[9:14], "big"),
                      "min_period": int.from_bytes(raw[14:19], "big"), "width": struct.unpack_from(">H", raw, 19)[0]}
            merged = {name: fields[name] if apply >> i & 1 else self.config[name] for i, name in enumerate(NAMES)}
            if any(records.master_config_faults(merged).values()):
                return self._drop("drop_app_value")
        if self._previous is not None and sequence != (self._previous + 1) & 0xFF:
            self.counters["sequence_gaps"] += 1
        self._previous = sequence
        if kind == MASTER_CONTROL:
            self.config = merged
            self.counters["records_control"] += 1
            if action & 1 and merged["mode"] == TriggerMode.SOFTWARE and merged["armed"]:
                self.counters["pulses"] += 1
            return None
        self.counters["records_status"] += 1
        return codec.master_status_reply(sequence, {**self.counters, **self.config, "clock_hz": self.CLOCK_HZ,
                                                    "boards": 4, "ready": 0b1111})


@pytest.fixture
def master():
    server = FakeMaster().start()
    yield server
    server.close()


def test_master_control_record_bytes():
    """Only the given fields' ``apply`` bits, the software trigger as action bit 0; an unknown
    field is refused as the projector's control record refuses one."""
    raw = codec.master_control_record(7, software_trigger=True, mode=2, period=0x0102030405, width=300)
    assert raw == control_bytes(7, 0b10101, 1, mode=2, period=0x0102030405, width=300)
    assert codec.master_control_record(300, armed=1, min_period=9) == control_bytes(300 & 0xFF, 0b01010, 0,
                                                                                    armed=1, min_period=9)
    head, body, rest = codec.decode(raw)
    assert (head["type"], head["sequence"], rest) == (MASTER_CONTROL, 7, b"")
    assert body == {"apply": 0b10101, "action": 1, "mode": 2, "armed": 0, "period": 0x0102030405,
                    "min_period": 0, "width": 300}
    with pytest.raises(KeyError, match="bit_depth"):
        codec.master_control_record(bit_depth=8)
    # the projector's control record, built by the same helper, keeps its own table
    assert codec.control_record(1, armed=1)[5:8] == struct.pack(">HB", 0b10, 0)


def test_master_status_reply_decodes():
    """Type 9, 192 bytes: the network counters, the master's record counters, then its own
    figures (offsets as the protocol page gives them)."""
    values = {"records_status": 11, "uptime_cycles": 2**47 + 5, "clock_hz": 125_000_000, "boards": 4,
              "ready": 0b1011, "pulses": 77, "mode": 1, "period": 2**39 + 1, "width": 125, "mac_tx_underruns": 3}
    raw = codec.master_status_reply(300, values)
    assert len(raw) == 192 and struct.unpack_from(HEADER, raw) == (0x444D, records.VERSION, MASTER_STATUS, 300 & 0xFF)
    assert struct.unpack_from(">I", raw, 93)[0] == 11                   # records_status
    assert int.from_bytes(raw[121:127], "big") == 2**47 + 5              # uptime_cycles
    assert struct.unpack_from(">IBHI", raw, 127) == (125_000_000, 4, 0b1011, 77)
    assert raw[146] == 1 and int.from_bytes(raw[148:153], "big") == 2**39 + 1
    assert struct.unpack_from(">H", raw, 158)[0] == 125 and struct.unpack_from(">I", raw, 188)[0] == 3
    head, body, rest = codec.decode(raw)
    assert head["type"] == MASTER_STATUS and rest == b""
    assert {name: body[name] for name in values} == values
    assert body["drop_app_magic"] == 0 and len(body) == len(records.MASTER_STATUS_REPLY)
    with pytest.raises(codec.ProtocolError, match="record type 9 is 192 bytes, got 193"):
        codec.decode(raw + b"\0")


def test_status_waits_for_each_devices_own_reply(master):
    """A master client reads the master's status; a projector client waits for a projector's
    reply and takes the master's for none."""
    with MasterClient("127.0.0.1", master.port) as client:
        status = client.status()
    assert (status["clock_hz"], status["boards"], status["ready"]) == (125_000_000, 4, 0b1111)
    assert status["min_period"] == 125_000 and status["records_status"] == 1
    with Client("127.0.0.1", master.port, timeout=0.1) as client:
        with pytest.raises(ClientError, match="no status reply from 127.0.0.1.*after 1 tries"):
            client.status(retries=0)
    assert master.counters["records_status"] == 2


def test_configure_sends_cycles_of_the_masters_clock(master):
    """Seconds become the nearest whole cycle of the clock the status gives; one record applies
    just the fields given, the others keep the values in force."""
    with MasterClient("127.0.0.1", master.port) as client:
        now = client.configure(mode=TriggerMode.PERIODIC, armed=True, period_s=0.0040000031, min_period_s=0.0035,
                               width_s=1.006e-6)
        expected = {"mode": 1, "armed": 1, "period": 500_000, "min_period": 437_500, "width": 126}
        assert now == expected
        client.status()              # the record has been taken when its answer comes
        assert master.config == expected
        assert master.received[1] == control_bytes(1, 0b11111, 0, **expected)
        assert client.configure(width_s=2e-6) == {**expected, "width": 250}
        client.status()
    assert master.received[4] == control_bytes(4, 0b10000, 0, width=250)
    assert master.config == {**expected, "width": 250}
    assert master.kinds() == [STATUS_QUERY, MASTER_CONTROL, STATUS_QUERY, STATUS_QUERY, MASTER_CONTROL, STATUS_QUERY]
    assert master.counters["records_control"] == 2 and master.counters["sequence_gaps"] == 0


@pytest.mark.parametrize(("settings", "failed"), [
    ({"width_s": 0.002}, "width_below_min_period, width_fits$"),     # 250,000 cycles: over 16 bits
    ({"min_period_s": 1e-6}, "width_below_min_period$"),             # 125 cycles, as long as the pulse
    ({"mode": TriggerMode.SYNC}, ": mode$"),
    ({"armed": 2}, ": armed$"),
    ({"mode": TriggerMode.PERIODIC, "period_s": 0.0005}, "period_keepable$"),   # under min_period
    ({"period_s": 2**40 / 125e6}, "period_fits$"),
    ({"period_s": -1.0}, "period_fits"),
])
def test_configure_refuses_what_the_master_would_drop(master, settings, failed):
    """Checked on the configuration the record would leave in force, before anything is sent:
    the master sees the status query and no control record."""
    with MasterClient("127.0.0.1", master.port) as client:
        with pytest.raises(ClientError, match=f"the sync master cannot take this configuration .*{failed}"):
            client.configure(**settings)
        client.status()
    assert master.kinds() == [STATUS_QUERY, STATUS_QUERY]
    assert master.config["min_period"] == 125_000 and master.counters["drop_app_value"] == 0


def test_trigger_sends_the_software_trigger_alone(master):
    with MasterClient("127.0.0.1", master.port) as client:
        client.configure(mode=TriggerMode.SOFTWARE, armed=True)
        client.trigger()
        assert client.status()["pulses"] == 1
    assert master.received[2] == (struct.pack(HEADER + "BB", 0x444D, records.VERSION, MASTER_CONTROL, 2, 0, 1)
                                  + bytes(14))
    assert master.config == {"mode": 2, "armed": 1, "period": 0, "min_period": 125_000, "width": 125}


def test_cli_master(master, capsys):
    """``python -m host master ADDRESS``: settings in seconds, then the trigger, then the status;
    the status alone when nothing else is asked; a configuration the master would drop refused
    before it is sent."""
    base = ["--timeout", "1", "master", "127.0.0.1", "--port", str(master.port)]
    assert cli.main(base + ["--mode", "software", "--arm", "--period", "0.002", "--min-period", "0.001",
                            "--width", "2e-6", "--trigger", "--status"]) == 0
    out = capsys.readouterr().out
    assert "sync master: mode software, armed, period 250000, min_period 125000, width 250 cycles\n" in out
    assert "\npulses                   1\n" in out and "\nclock_hz                 125000000\n" in out
    assert master.config == {"mode": 2, "armed": 1, "period": 250_000, "min_period": 125_000, "width": 250}
    assert master.kinds() == [STATUS_QUERY, MASTER_CONTROL, MASTER_CONTROL, STATUS_QUERY]
    assert master.received[2][5:7] == bytes([0, 1])                     # the trigger applies nothing
    # --port before the command serves as well; with nothing asked, the status alone
    assert cli.main(["--port", str(master.port), "master", "127.0.0.1"]) == 0
    assert "\nrecords_control          2\n" in capsys.readouterr().out
    # (with the status after it: the fake master handles records in order, on its own thread)
    assert cli.main(base + ["--disarm", "--status"]) == 0
    assert master.received[-2] == control_bytes(1, 0b00010, 0) and master.config["armed"] == 0
    assert "disarmed" in capsys.readouterr().out
    sent = len(master.received)
    assert cli.main(base + ["--width", "0.01"]) == 1
    assert "error: the sync master cannot take this configuration" in (err := capsys.readouterr().err)
    assert "width_fits" in err and master.kinds()[sent:] == [STATUS_QUERY]
    for wrong in (["--arm", "--disarm"], ["--mode", "sync"], ["--period", "soon"]):
        with pytest.raises(SystemExit) as leaving:
            cli.main(base + wrong)
        assert leaving.value.code == 2


def test_cli_configure_group_orders_sends_each_groups_order(projector, capsys):
    """``configure --group-orders``: the solver's plan (each group its own order and offset) is
    printed group by group and sent as the projector takes it; the schedule model plays the set
    the projector took with no pulse late. Options it does not plan for are refused."""
    from spec import group_orders, registers
    base = ["--address", "127.0.0.1", "--port", str(projector.port)]
    setting = ["configure", "--dmd", "test", "--dclk", "200e6", "--reset-mode", "SINGLE", "--group-orders", "3"]
    assert cli.main(base + setting) == 0
    assert cli.main(base + ["status"]) == 0
    model = projector.model
    assert model.counters["records_sequencer"] == 1 and model.counters["drop_app_value"] == 0
    taken = registers.unpack(records.registers_bits(model.registers[-1]))
    assert taken["order"] == PlaneOrder.GROUPS
    out = capsys.readouterr().out
    tables = [tuple(taken["group_tables"][8 * g:8 * g + 8]) for g in range(TEST_DMD.blocks)]
    for g, table in enumerate(tables):
        assert f"group {g:2}  offset {taken['group_offsets'][g]:>7}  order {' '.join(map(str, table))}" in out
    # the tables and offsets taken, played by the model on the finder's base plan: no pulse late
    _, start = group_orders.sequencer_terms(TEST_DMD, 200e6, ResetMode.SINGLE)
    offsets = taken["group_offsets"][:TEST_DMD.blocks]
    plan = group_orders.played(TEST_DMD, start, taken["lsb"], tables, offsets)
    assert plan is not None and records.register_wire(plan.params.registers(TEST_DMD)) == model.registers[-1]
    assert f"{plan.rate_hz:.1f} frames/s" in out
    assert cli.main(base + setting + ["--depth", "6"]) == 1
    assert "not with --depth" in capsys.readouterr().err
    # chained: the register set chains frames, and is the chained plan the model plays on time
    assert cli.main(base + setting + ["--chained"]) == 0
    assert cli.main(base + ["status"]) == 0
    assert model.counters["records_sequencer"] == 2 and model.counters["drop_app_value"] == 0
    taken = registers.unpack(records.registers_bits(model.registers[-1]))
    assert taken["chain"] and taken["order"] == PlaneOrder.GROUPS
    tables = [tuple(taken["group_tables"][8 * g:8 * g + 8]) for g in range(TEST_DMD.blocks)]
    chained = dataclasses.replace(start, params=dataclasses.replace(start.params, chain=True))
    plan = group_orders.played(TEST_DMD, chained, taken["lsb"], tables, taken["group_offsets"][:TEST_DMD.blocks])
    assert plan is not None and records.register_wire(plan.params.registers(TEST_DMD)) == model.registers[-1]
    assert cli.main(base + ["configure", "--dmd", "test", "--chained"]) == 1
    assert "--chained plans with --group-orders" in capsys.readouterr().err
