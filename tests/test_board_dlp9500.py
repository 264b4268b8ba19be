"""The DLP9500's board (the SVEC with the two-FMC DLPC410 adapter): every DLPC410 pin of a four-bus
DMD on a pin of its own, the high-speed ones LVDS; the platform top's ISE tree for it (built with
the small four-bus DMD, which elaborates in seconds: ``make verilog`` builds the DLP9500's);
the Atlys refuses a four-bus DMD; the PLLs from the SVEC's 125 MHz oscillator."""

import re

import pytest
from amaranth.build import DiffPairs
from amaranth.hdl import Shape

from flow import verilog
from gateware.dlpc410.interface import PINS_PER_BUS, Signature
from gateware.platform import BOARDS
from gateware.platform.clocks import PLANS, pll_multipliers
from gateware.platform.dlpc410_adapter import CONTROL_LINES, TRIGGER_LINES
from gateware.platform.mcb_instance import McbInstance
from gateware.platform.svec import SVEC_DDR3
from gateware.top.platform import PlatformTop
from sim.harness.paths import build_dir

BUSES = "abcd"


def expected_pins():
    """{resource subsignal: (width, differential)} a four-bus DMD's DLPC410 link needs, from the
    core's interface: DIN, DCLK and DVALID per bus as pairs, every other member single-ended."""
    want = {}
    for name, member in Signature(4, 1).members.items():
        if name.startswith("din_"):
            want[name] = (PINS_PER_BUS, True)
        elif name == "dvalid":
            want.update({f"dvalid_{bus}": (1, True) for bus in BUSES})
        else:
            want[name] = (Shape.cast(member.shape).width, False)
    want.update({f"dclk_{bus}": (1, True) for bus in BUSES})
    return want


def fpga_pins(platform, resource, io):
    """The FPGA pins of ``io`` (Pins or DiffPairs, both halves): connector pins mapped through the
    board's connectors."""
    mapping = {f"{c.name}_{c.number}:{pin}": loc
               for c in platform.connectors.values() for pin, loc in c.mapping.items()}
    if isinstance(io, DiffPairs):
        return io.p.map_names(mapping, resource) + io.n.map_names(mapping, resource)
    return io.map_names(mapping, resource)


def board_pins(platform, name):
    """{subsignal: (FPGA pins, differential, attrs)} of resource ``name``."""
    resource = platform.lookup(name, 0)
    return {sub.name: (fpga_pins(platform, resource, sub.ios[0]), isinstance(sub.ios[0], DiffPairs), sub.attrs)
            for sub in resource.ios}


def test_adapter_carries_every_pin_of_a_four_bus_dmd_once():
    platform = BOARDS["svec"]()
    fast, ext = board_pins(platform, "dlpc410"), board_pins(platform, "dlpc410_ext")
    got = {**fast, **ext}
    assert len(got) == len(fast) + len(ext), "a signal in both resources"
    want = expected_pins()
    assert set(got) == set(want)
    for name, (width, differential) in want.items():
        pins, is_pair, attrs = got[name]
        assert is_pair == differential, name
        assert len(pins) == width * (2 if differential else 1), name
        assert attrs["IOSTANDARD"] == ("LVDS_25" if differential else "LVCMOS25"), name
    # every DIN bit, DCLK and DVALID of A..D on the FMC slots: 72 pairs, and the 35 control lines
    pairs = [pin for pins, is_pair, _ in got.values() if is_pair for pin in pins]
    single = [pin for pins, is_pair, _ in got.values() if not is_pair for pin in pins]
    assert len(pairs) == 2 * 72 and len(single) == sum(w for _n, w, _d in CONTROL_LINES) == 35
    # no FPGA pin twice, within the link or with the board's other resources
    triggers = [pin for name, _dir in TRIGGER_LINES
                for pin in fpga_pins(platform, platform.lookup(name, 0), platform.lookup(name, 0).ios[0])]
    everything = pairs + single + triggers
    assert len(everything) == len(set(everything)) == 2 * 72 + 35 + 5


def test_each_fmc_slot_carries_two_buses_whole():
    """Buses A and B on the first slot, C and D on the second: each bus's lanes, DCLK and DVALID
    on one mezzanine (one connector's skew)."""
    platform = BOARDS["svec"]()
    slots = {}
    for sub in platform.lookup("dlpc410", 0).ios:
        conns = {name.split(":")[0] for name in sub.ios[0].p.names + sub.ios[0].n.names}
        assert len(conns) == 1, sub.name
        slots[sub.name] = conns.pop()
    for bus, slot in zip(BUSES, ("fmc_0", "fmc_0", "fmc_1", "fmc_1"), strict=True):
        for kind in ("din", "dclk", "dvalid"):
            assert slots[f"{kind}_{bus}"] == slot, f"{kind}_{bus}"


@pytest.fixture(scope="module")
def svec_tree():
    out = build_dir("test_board_dlp9500", "dlp9500")
    top = verilog.emit_dlp9500(out, dmd="test4_400")
    return out, top


def test_tree_places_the_whole_link(svec_tree):
    out, top = svec_tree
    for name in (f"{top}.v", f"{top}.ucf", f"{top}.prj", f"{top}.xst", f"build_{top}.sh"):
        assert (out / name).is_file(), name
    ucf = (out / f"{top}.ucf").read_text()
    locs = re.findall(r'NET "([^"]+)" LOC=(\w+);', ucf)
    placed = [loc for _net, loc in locs]
    assert len(placed) == len(set(placed)), "an FPGA pin placed twice"
    nets = {net for net, _loc in locs}
    for bus in BUSES:
        for side in "pn":
            assert {f"dlpc410_0__din_{bus}__{side}<{i}>" for i in range(PINS_PER_BUS)} <= nets, bus
            assert f"dlpc410_0__dclk_{bus}__{side}" in nets and f"dlpc410_0__dvalid_{bus}__{side}" in nets
    for name, width, _dir in CONTROL_LINES:
        got = {net for net in nets if net.startswith(f"dlpc410_ext_0__{name}__")}
        assert len(got) == width, name
    fast = {net for net in nets if net.startswith("dlpc410_0__")}
    assert len(fast) == 2 * 72
    assert all(f'NET "{net}" IOSTANDARD=LVDS_25;' in ucf for net in fast)
    assert "xc6slx150tfgg900-3" in (out / f"{top}.xst").read_text()
    assert re.search(r'PERIOD "PRDclk125_0__p" 8\.0 ns', ucf)
    v = (out / f"{top}.v").read_text()
    # a serialiser per lane: 64 DIN, 4 DVALID, 4 DCLK
    assert len(re.findall(r"^\s+OSERDES2 #\(", v, re.M)) == 72
    assert re.search(rf"^\s+{SVEC_DDR3.module} mcb \(", v, re.M)
    # the Ethernet PHY: our PCS on one GTP lane, its two user clocks through BUFIO2s and BUFGs
    assert len(re.findall(r"^\s+GTPA1_DUAL #\(", v, re.M)) == 1
    assert re.search(r"\.PLL_DIVSEL_FB_0\(32'd2\)", v), "1.25 Gb/s from 125 MHz"
    assert len(re.findall(r"^\s+BUFIO2 #\(", v, re.M)) >= 2
    assert re.search(r"^module \\projector_dlp9500\.gmii\.phy\.pcs ", v, re.M), "the PCS"
    # the clock loop's DAC: the VCXO behind the 125 MHz reference (the reference design's pins)
    assert {("vcxo_dac_0__sclk__io", "N27"), ("vcxo_dac_0__din__io", "P25"),
            ("vcxo_dac_0__sync_n__io", "P26")} <= set(locs)
    assert re.search(r"^\s+\S*\.trim_dac\s+trim_dac \(", v, re.M), "the DAC writer"
    # the sync input on both edges in its pad: the falling half is the clock loop's detector
    pads = [body for body in v.split("\nmodule ")[1:]
            if re.match(r"\\projector_dlp9500\.trigger\S*\.sync_in\S* ", body)]
    assert any("IDDR2 #(" in body.split("endmodule")[0] for body in pads), "sync_in's IDDR2"


def test_tree_lints_clean(svec_tree):
    out, top = svec_tree
    ok, messages = verilog.lint_top(out / f"{top}.v", top, verilog.blackboxes("svec"), workdir=out.parent / "lint")
    assert ok, messages


def test_lint_top_reports_a_module_it_cannot_declare(tmp_path):
    top = tmp_path / "top.v"
    top.write_text("module top(input a, output b);\n  NOT_A_PRIMITIVE u (\n    .I(a),\n    .O(b)\n  );\nendmodule\n")
    ok, messages = verilog.lint_top(top, "top")
    assert not ok and "NOT_A_PRIMITIVE" in messages


def test_atlys_refuses_a_four_bus_dmd():
    with pytest.raises(ValueError, match="carries 2 buses, the DMD needs 4"):
        BOARDS["atlys"]().prepare(PlatformTop(dmd="test4_400"), name="projector")


def test_plls_from_each_board_oscillator():
    assert [pll_multipliers(100e6, plan["vco"]) for plan in PLANS[400e6]] == [(1, 10), (1, 8)]
    # 800 MHz from 125 MHz: the phase detector at 25 MHz
    assert [pll_multipliers(125e6, plan["vco"]) for plan in PLANS[400e6]] == [(1, 8), (5, 32)]
    with pytest.raises(AssertionError):
        pll_multipliers(27e6, 800)          # a 1 MHz phase detector


def test_ddr3_controller_ports():
    text = McbInstance.blackbox_verilog(SVEC_DDR3)
    assert re.search(r"^module svec_ddr3 \(", text, re.M)
    assert re.search(r"inout \[13:0\] mcb4_dram_a", text) and "mcb4_dram_reset_n" in text
    assert "zio" not in text and "c4_p1_rd_data" in text
