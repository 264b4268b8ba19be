"""The harnesses themselves: layouts round-trip, a failing cocotb test fails pytest
(:mod:`sim.tb.selfcheck_tb`), and runs of one build at the same time (pytest-xdist workers) each
report their own result."""

import random
import threading

import pytest
from amaranth import Module, signed
from amaranth.lib import data, wiring
from amaranth.lib.wiring import Out
from cocotb_tools.check_results import get_results

from gateware.bitplane import word_layout
from sim.harness import cocotb_run
from sim.harness.layout import pack, unpack
from spec.facts import TEST_DMD


def test_layout_round_trip():
    layout = word_layout(TEST_DMD)
    value = {"data": 0x8000_0000_0000_0001, "plane": 5, "word": 1, "block": 3, "frame": 9, "base": 7,
             "carried": 12, "row": 95}
    assert unpack(layout, pack(layout, value)) == value
    nested = data.StructLayout({"a": data.ArrayLayout(8, 3), "b": 4})
    assert unpack(nested, pack(nested, {"a": [1, 2, 255], "b": 7})) == {"a": [1, 2, 255], "b": 7}


def test_pack_and_unpack_agree_with_amaranth():
    """The shifts and masks give the bits of the layout's own ``const`` (values truncated to
    their fields, signed fields in two's complement), and read them back as ``data.Const`` does."""
    layout = data.StructLayout({"a": data.ArrayLayout(signed(5), 3), "b": 7, "c": data.StructLayout({"d": 1, "e": 9})})
    rng = random.Random(5)
    for _ in range(200):
        value = {"a": [rng.randrange(-40, 40) for _ in range(3)], "b": rng.randrange(1000),
                 "c": {"d": rng.randrange(3), "e": rng.randrange(600)}}
        bits = pack(layout, value)
        assert bits == layout.const(value).as_value().value
        const = data.Const(layout, bits)
        assert unpack(layout, bits) == {"a": [const.a[i] for i in range(3)], "b": const.b,
                                        "c": {"d": const.c.d, "e": const.c.e}}


class Counter(wiring.Component):
    count: Out(8)

    def elaborate(self, platform):
        m = Module()
        m.d.sync += self.count.eq(self.count + 1)
        return m


@pytest.mark.verilog
def test_failing_cocotb_test_fails_pytest():
    with pytest.raises(AssertionError, match="1 of 1 cocotb tests failed"):
        cocotb_run.run(Counter(), toplevel="counter", module="sim.tb.selfcheck_tb", key="selfcheck",
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
            cocotb_run.run(Counter(), toplevel="counter", module="sim.tb.selfcheck_tb", key="selfcheck",
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
