"""The MCB instance for the Spartan-6 top: the vendor wrapper gets every user-port signal of
both ports and every DDR2 pin, with the widths the generator gives them."""

import re

from amaranth import Module
from amaranth.back import verilog
from amaranth.lib import wiring

from gateware.platform.mcb_instance import MODULE, McbInstance
from gateware.store import mcb
from gateware.store.store import Store
from spec.facts import TEST_DMD


def test_instance_ports():
    top = Module()
    top.submodules.store = store = Store(TEST_DMD)
    top.submodules.mcb = inst = McbInstance()
    wiring.connect(top, store.mcb_write, inst.port0)
    wiring.connect(top, store.mcb_read, inst.port1)
    text = verilog.convert(top, ports=[], name="top")
    body = text[text.index(f"{MODULE} mcb"):]
    body = body[:body.index(");")]
    connected = set(re.findall(r"\.(\w+)\(", body))
    for n in (0, 1):
        for name in mcb.PortSignature().members:
            if name != "calib_done":
                assert f"c3_p{n}_{name}" in connected, f"c3_p{n}_{name} not connected"
        for clock in ("cmd_clk", "wr_clk", "rd_clk"):
            assert f"c3_p{n}_{clock}" in connected
    for pin in ("mcb3_dram_dq", "mcb3_dram_a", "mcb3_dram_ba", "mcb3_dram_udqs", "mcb3_dram_dqs_n",
                "mcb3_rzq", "mcb3_zio", "c3_calib_done", "c3_sys_clk", "c3_sys_rst_i"):
        assert pin in connected
    assert re.search(r"inout \[15:0\] mcb3_dram_dq", text)
    assert re.search(r"inout \[12:0\] mcb3_dram_a", text)
