import os
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


def pytest_terminal_summary(terminalreporter, exitstatus, config):
    """The suite prints its own wall time, against its budget."""
    if hasattr(config, "workerinput"):
        return
    wall = time.monotonic() - _started
    workers = getattr(config.option, "numprocesses", None) or 1
    terminalreporter.write_line(
        f"suite wall time: {wall:.0f} s on {workers} worker(s) (budget {BUDGET_S} s on 2 cores)")
