"""The harnesses themselves: layouts round-trip, and a failing cocotb test fails pytest."""

import pytest
from amaranth import Module
from amaranth.lib import data, wiring
from amaranth.lib.wiring import Out

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
        cocotb_run.run(Counter(), toplevel="counter", module="sim.tb.selfcheck", key="selfcheck")
