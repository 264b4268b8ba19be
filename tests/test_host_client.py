"""The host client and CLI against an in-process UDP server on 127.0.0.1 that plays projector
with the reference model."""

import socket
import threading

import numpy as np
import pytest

from host import Client, ClientError, cli, codec
from sim.models.net import Model
from spec import records
from spec.facts import TEST_DMD


class FakeProjector:
    """Decodes every datagram with the reference model; answers status queries (or, with
    ``mode``, answers badly or not at all)."""

    def __init__(self, mode="good"):
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.bind(("127.0.0.1", 0))
        self.sock.settimeout(0.05)
        self.port = self.sock.getsockname()[1]
        self.model = Model(TEST_DMD, 0x020000000001, 0x7F000001, self.port)
        self.mode = mode
        self.received = []
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._serve, daemon=True)
        self._thread.start()

    def _serve(self):
        while not self._stop.is_set():
            try:
                raw, sender = self.sock.recvfrom(65536)
            except socket.timeout:
                continue
            self.received.append(raw)
            replies_before = len(self.model.replies)
            self.model.record(raw)
            if len(self.model.replies) > replies_before and self.mode != "silent":
                sequence = self.model.replies[-1][1]["sequence"]
                values = {name: self.model.counters.get(name, 0) for name, _ in records.STATUS_REPLY}
                reply = codec.status_reply(sequence, values)
                if self.mode == "garbled":
                    reply = reply[:20]
                self.sock.sendto(reply, sender)

    def close(self):
        self._stop.set()
        self._thread.join()
        self.sock.close()


@pytest.fixture
def projector(request):
    server = FakeProjector(getattr(request, "param", "good"))
    yield server
    server.close()


def test_send_image_and_status(projector):
    image = np.random.default_rng(1).integers(0, 256, (TEST_DMD.rows, TEST_DMD.columns), dtype=np.uint8)
    with Client("127.0.0.1", projector.port, timeout=1.0, rate=50e6) as client:
        sent = client.send_image(image, frame=3)
        client.control(armed=1, software_trigger=True)
        status = client.status()
    assert sent == 2   # 64 rows + 32 rows of 128 bytes
    assert status["records_image"] == 2 and status["records_control"] == 1
    assert status["rows"] == TEST_DMD.rows and status["sequence_gaps"] == 0
    rows = {row: data for _tag, row, data in projector.model.rows}
    assert all(rows[r] == image[r].tobytes() for r in range(TEST_DMD.rows))
    assert projector.model.triggers == 1 and projector.model.config["armed"] == 1


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
    with Client("127.0.0.1", projector.port, rate=200e3) as client:
        start = time.monotonic()
        client.send_sequence([image] * 3)
        elapsed = time.monotonic() - start
    # 6 records of ~8 kB and ~4 kB: the last one may leave at 5/6 of 37 kB / 200 kB/s
    assert elapsed >= 0.1


def test_cli_send_and_status(projector, tmp_path, capsys):
    path = tmp_path / "scene.npy"
    np.save(path, np.full((TEST_DMD.rows, TEST_DMD.columns), 9, np.uint8))
    base = ["--address", "127.0.0.1", "--port", str(projector.port)]
    assert cli.main(base + ["send", str(path), "--frame", "2"]) == 0
    assert "sent 1 frame(s) in 2 records" in capsys.readouterr().out
    assert cli.main(base + ["status"]) == 0
    assert "records_image" in capsys.readouterr().out
    assert cli.main(base + ["send", str(tmp_path / "missing.npy")]) == 1
    assert "error: cannot read" in capsys.readouterr().err


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
    assert cli.main(base + ["configure", "--dmd", "test", "--depth", "6", "--dry-run"]) == 0
    out = capsys.readouterr().out
    assert f"{plan.rate_hz:.1f} frames/s ({plan.frame_cycles} DCLK cycles per frame)" in out
    assert projector.received == []
    assert cli.main(base + ["configure", "--dmd", "test", "--depth", "6"]) == 0
    assert cli.main(base + ["arm"]) == 0
    assert cli.main(base + ["status"]) == 0
    model = projector.model
    assert model.counters["records_sequencer"] == 1 and model.counters["drop_app_value"] == 0
    assert model.registers == [records.register_wire(plan.params.registers(TEST_DMD))]
    assert model.config["bit_depth"] == 6 and model.config["armed"] == 1


def test_sequencer_record_refuses_what_the_projector_would_drop():
    from spec import schedule
    wire = records.register_wire(schedule.plan(TEST_DMD, 200e6).params.registers(TEST_DMD))
    codec.sequencer_record(wire, dmd=TEST_DMD)
    with pytest.raises(ValueError, match="lsb_even_nonzero"):
        codec.sequencer_record({**wire, "lsb": 3}, dmd=TEST_DMD)
    with pytest.raises(ValueError, match="order_known"):
        codec.sequencer_record({**wire, "order": 3}, dmd=TEST_DMD)
    head, body, rest = codec.decode(codec.sequencer_record(wire, 9))
    assert head["type"] == records.RecordType.SEQUENCER and body == wire and rest == b""
