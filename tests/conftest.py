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
BUDGET_S = 720

_started = time.monotonic()

#: The longest tests (``--durations``, 20 s and more on two workers), started first: the workers
#: then share them out and end on short tests together, instead of one waiting on the other's
#: last long one.
LONGEST_FIRST = (
    "test_system_xga.py::test_xga_frames_end_to_end",
    "test_system_xga.py::test_binary_patterns_from_the_store_while_gige_writes",
    "test_system_verilog.py::test_system_small_geometry",
    "test_tiled_verilog.py::test_tiled_boards_follow_the_master",
    "test_system_verilog.py::test_system_sequence_entries",
    "test_formal.py::test_property",
    "test_ethernet_verilog.py::test_ethernet_verilog",
    "test_tiled_verilog.py::test_tiled_boards_lock_their_clocks_to_the_master",
    "test_flow.py::test_ise_tree_has_verilog_ucf_and_scripts",
    "test_virtual_projector.py::test_installed_host_cli_through_the_kernel_to_the_core",
    "test_dlpc410_sequencer_verilog.py::test_sequencer_verilog_xga",
    "test_store.py::test_sequence_slots_walked_on_mode_change_and_loss",
    "test_store_verilog.py::test_store_verilog",
    "test_protocol_endpoint_verilog.py::test_endpoint_verilog",
    "test_dlpc410_ready.py::test_ready_line_tells_when_a_trigger_is_obeyed_at_once",
)


def pytest_collection_modifyitems(session, config, items):
    """The longest tests first (:data:`LONGEST_FIRST`), in that order; the others as collected."""
    def rank(item):
        name = item.nodeid.split("/")[-1].split("[")[0]
        return LONGEST_FIRST.index(name) if name in LONGEST_FIRST else len(LONGEST_FIRST)
    items.sort(key=rank)


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
    if config.option.markexpr == "formal":      # make properties: no budget of its own
        terminalreporter.write_line(f"formal properties wall time: {wall:.0f} s on {workers} worker(s)")
        return
    terminalreporter.write_line(
        f"suite wall time: {wall:.0f} s on {workers} worker(s) (budget {BUDGET_S} s on 2 cores)")
