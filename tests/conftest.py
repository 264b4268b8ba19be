import os
import secrets
import time

import pytest

from sim.harness import cxx_build
from sim.harness.paths import build_dir

# Waves are for looking at, not for every run: a test writes its VCD and GTKWave save file only
# when asked (WAVES=1), which keeps the whole suite fast.
os.environ.setdefault("WAVES", "0")

# Verilator builds: the runtime every build compiles (about 25 s of CPU) compiled once and copied,
# the design's C++ at a quicker optimisation level.
cxx_build.enable(build_dir("cocotb", "objcache"))

#: The suite's budget on two cores (README).
BUDGET_S = 900

_started = time.monotonic()


@pytest.fixture
def test_name(request):
    """The test's node id, used to name its VCD and build directory."""
    return request.node.name


@pytest.fixture
def seed(request):
    """A fresh seed for a randomised test each run, or ``SEED=n`` to replay one. It is printed
    (pytest shows it with a failing test's output) with the command that replays it."""
    value = int(os.environ.get("SEED") or secrets.randbits(32))
    print(f"seed {value}: replay with SEED={value} pytest '{request.node.nodeid}'")
    request.node.user_properties.append(("seed", value))
    return value


def pytest_terminal_summary(terminalreporter, exitstatus, config):
    """The suite prints its own wall time, against its budget."""
    if hasattr(config, "workerinput"):
        return
    wall = time.monotonic() - _started
    workers = getattr(config.option, "numprocesses", None) or 1
    terminalreporter.write_line(
        f"suite wall time: {wall:.0f} s on {workers} worker(s) (budget {BUDGET_S} s on 2 cores)")
