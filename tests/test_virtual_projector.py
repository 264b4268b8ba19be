"""The virtual projector (:mod:`sim.rigs.virtual_run`; testbenches
:mod:`sim.tb.virtual_projector_tb` and :mod:`sim.tb.virtual_master_tb`): real host software,
installed in a fresh virtual environment without Amaranth, talks through the operating system's
network stack (a namespace of its own) to the core's generated Verilog on a TAP device, and the
frame it sends is the frame the DMD shows. Skipped, with the reason, where the machine does not
allow a network namespace and a TAP device."""

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from sim.rigs import virtual_run as virtual

REASON = virtual.unavailable()
ROOT = Path(__file__).resolve().parents[1]
#: What pip says when it cannot reach a package index (a machine without one skips; any other
#: failure of the install is a failure of the package).
UNREACHABLE = ("Failed to establish a new connection", "Temporary failure in name resolution",
               "No matching distribution found", "Could not find a version that satisfies")


def host_environment(tmp_path):
    """A fresh virtual environment with this project installed as a user installs it on a lab PC
    (``pip install .``: the host library and CLI, numpy its one dependency, from the package
    index pip is configured with), from a copy of the sources without build products."""
    src, env = tmp_path / "src", tmp_path / "env"
    shutil.copytree(ROOT, src, ignore=shutil.ignore_patterns(".git", ".venv", "build", "*.egg-info", "__pycache__",
                                                              ".*_cache", ".hypothesis"))
    subprocess.run([sys.executable, "-m", "venv", str(env)], check=True, timeout=300)
    done = subprocess.run([str(env / "bin" / "pip"), "install", "--quiet", str(src)], capture_output=True,
                          text=True, timeout=600, cwd=tmp_path)
    if done.returncode and any(text in done.stderr for text in UNREACHABLE):
        pytest.skip(f"no package index reachable for pip: {done.stderr.strip().splitlines()[-1]}")
    assert done.returncode == 0, done.stderr
    return env / "bin" / "python"


@pytest.mark.verilog
@pytest.mark.skipif(REASON is not None, reason=f"virtual projector: {REASON}")
def test_installed_host_cli_through_the_kernel_to_the_core(tmp_path):
    python = host_environment(tmp_path)
    check = "import sys, host.cli; assert 'amaranth' not in sys.modules; print(host.__file__)"
    where = subprocess.run([str(python), "-c", check], check=True, capture_output=True, text=True,
                           cwd=tmp_path).stdout
    assert where.startswith(str(tmp_path / "env")), where
    gone = subprocess.run([str(python), "-c", "import amaranth"], capture_output=True, text=True, cwd=tmp_path)
    assert "ModuleNotFoundError" in gone.stderr

    report = virtual.demo(seconds=600, log=lambda _text: None, python=str(python), cwd=tmp_path)
    # the kernel ARPed for the projector, then pinged it; the CLI's records all got through
    assert report["ping_s"] > 0
    assert "records_status" in report["status_before"]
    assert "8-bit" in report["send"]
    # one frame triggered, one shown, exactly the image sent (the camera model on the pins)
    assert len(report["shown"]) == 1 and report["shown"][0]["whole_levels"]
    assert report["max_error_lsb"] == 0
    after = dict(line.split()[:2] for line in report["status_after"].splitlines() if len(line.split()) >= 2)
    assert after["frames_shown"] == "1" and after["triggers"] == "1"
    assert report["frames_received"] > 0 and report["frames_sent"] > 0 and report["stopped"] == "file"


@pytest.mark.verilog
@pytest.mark.skipif(REASON is not None, reason=f"virtual projector: {REASON}")
def test_host_cli_drives_the_sync_master_through_the_kernel():
    """``python -m host master`` in the namespace, through the kernel's ARP, IP and UDP, to the
    sync master's generated Verilog: its status, then software triggers armed and one fired: one
    pulse on the pins, of the width asked for, and the status says so."""
    report = virtual.master_demo(seconds=300, log=lambda _text: None)

    def fields(text):
        return dict(line.split()[:2] for line in text.splitlines() if len(line.split()) >= 2)
    before, after = fields(report["status_before"]), fields(report["status_after"])
    assert (before["pulses"], before["armed"], before["records_control"]) == ("0", "0", "0")
    assert "software" in report["configured"]
    assert (after["pulses"], after["armed"], after["mode"], after["records_control"]) == ("1", "1", "2", "2")
    assert after["width"] == "25" and after["min_period"] == "12500"       # 0.2 us, 100 us at 125 MHz
    # the pins: one pulse on every board's line and the camera's at once, 25 cycles long
    assert report["pulses"] == 1 and report["widths"] == [25]
    assert report["frames_received"] > 0 and report["frames_sent"] > 0 and report["stopped"] == "file"
