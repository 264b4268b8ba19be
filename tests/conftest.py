import os
import time

import pytest

# Waves are for looking at, not for every run: a test writes its VCD and GTKWave save file only
# when asked (WAVES=1), which keeps the whole suite fast.
os.environ.setdefault("WAVES", "0")

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
