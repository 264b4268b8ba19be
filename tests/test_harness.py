"""The harnesses themselves: layouts round-trip, a failing cocotb test fails pytest, and runs of
one build at the same time (pytest-xdist workers) each report their own result."""

import threading

import pytest
from amaranth import Module
from amaranth.lib import data, wiring
from amaranth.lib.wiring import Out
from cocotb_tools.check_results import get_results

from gateware.bitplane import word_layout
from sim.harness import cocotb_run
from sim.harness.layout import pack, unpack
from spec.facts import TEST_DMD


def test_layout_round_trip():
    layout = word_layout(TEST_DMD)
    value = {"data": 0x8000_0000_0000_0001, "plane": 5, "word": 1, "block": 3, "frame": 9, "row": 95}
    assert unpack(layout, pack(layout, value)) == value
    nested = data.StructLayout({"a": data.ArrayLayout(8, 3), "b": 4})
    assert unpack(nested, pack(nested, {"a": [1, 2, 255], "b": 7})) == {"a": [1, 2, 255], "b": 7}


class Counter(wiring.Component):
    count: Out(8)

    def elaborate(self, platform):
        m = Module()
        m.d.sync += self.count.eq(self.count + 1)
        return m


@pytest.mark.verilog
def test_failing_cocotb_test_fails_pytest():
    with pytest.raises(AssertionError, match="1 of 1 cocotb tests failed"):
        cocotb_run.run(Counter(), toplevel="counter", module="sim.tb.selfcheck", key="selfcheck",
                       testcase="wrong_expectation")


@pytest.mark.verilog
def test_concurrent_runs_of_one_build_report_their_own_results(tmp_path):
    """Two runs of the same build started together, one told to pass and one to fail: each has
    its own directory and results, and each call reports its own outcome."""
    outcome = {}
    start = threading.Barrier(2)

    def run(name, fail):
        start.wait()
        try:
            cocotb_run.run(Counter(), toplevel="counter", module="sim.tb.selfcheck", key="selfcheck",
                           testcase="fail_as_told", params={"cycles": 20_000, "fail": fail},
                           run_dir=tmp_path / name)
            outcome[name] = "passed"
        except AssertionError as error:
            outcome[name] = str(error)

    threads = [threading.Thread(target=run, args=("right", False)),
               threading.Thread(target=run, args=("wrong", True))]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert outcome["right"] == "passed"
    assert "1 of 1 cocotb tests failed" in outcome["wrong"] and str(tmp_path / "wrong") in outcome["wrong"]
    assert get_results(tmp_path / "right" / "results.xml") == (1, 0)
    assert get_results(tmp_path / "wrong" / "results.xml") == (1, 1)
