"""The build flow: the Spartan-6 tree, Verilator lint, the resource report and bench.json."""

import json

import pytest

from flow import bench, resources, verilog
from flow.blocks import BLOCKS
from sim.harness.paths import build_dir

# Each test builds only what it looks at (the platform's tree, every block's Verilog, one
# block's), so that tests spread over workers do not build the same files twice.


def test_ise_tree_has_verilog_ucf_and_scripts():
    out = build_dir("test_flow", "spartan6")
    top = verilog.emit_platform(out)
    for name in (f"{top}.v", f"{top}.ucf", f"{top}.prj", f"{top}.xst", f"build_{top}.sh"):
        assert (out / name).is_file(), name
    ucf = (out / f"{top}.ucf").read_text()
    # the oscillator's period constraint, the DLPC410 LVDS pins and the trigger input are placed
    assert "PERIOD" in ucf and "10.0 ns" in ucf
    assert 'NET "dlpc410_0__din_a__p<0>" LOC=U16;' in ucf
    assert "LVDS_25" in ucf
    assert "trigger_in_0__io" in ucf
    v = (out / f"{top}.v").read_text()
    for primitive in ("PLL_BASE", "BUFG", "ODDR2", "OBUFTDS"):
        assert primitive in v, primitive


@pytest.mark.parametrize("name", sorted(BLOCKS))
def test_block_lint_clean(name):
    """Each block's Verilog (one test each, so that the large ones spread over the workers)."""
    path = build_dir("test_flow", "lint") / f"{name}.v"
    path.write_text(verilog.block_verilog(name))
    (ok, messages), = verilog.lint({name: path}).values()
    assert ok, messages


def test_lint_reports_real_errors(tmp_path):
    bad = tmp_path / "broken.v"
    bad.write_text("module broken(input a, output b); assign b = c; endmodule\n")
    (ok, messages), = verilog.lint({"broken": bad}).values()
    assert not ok and "c" in messages


def test_cell_counting():
    cells = {"LUT6": 10, "LUT2": 3, "LUT6_2": 1, "RAM32M": 2, "SRLC32E": 1, "FDRE": 40, "FDCE": 2,
             "RAMB16BWER": 2, "RAMB8BWER": 3, "DSP48A1": 1, "CARRY4": 5, "IBUF": 9, "OSERDES2": 20,
             "PLL_ADV": 2, "BUFPLL": 2}
    assert resources.count(cells) == {"lut": 10 + 3 + 1 + 8 + 1, "ff": 42, "bram18": 3.5, "dsp": 1,
                                      "oserdes2": 20, "pll": 2, "bufpll": 2}


def test_serialiser_synthesises_to_its_registers():
    path = build_dir("test_flow", "synth") / "serialiser.v"
    path.write_text(verilog.block_verilog("serialiser"))
    counts = resources.count(resources.synthesise(path, "serialiser"))
    # registers by design: 8 held words of 64 bits, and 8 planes assembling all but the last
    # lanes=8 bits of a word (the last 8 come straight from the input)
    assert counts["ff"] >= 8 * 64 + 8 * (64 - 8)
    assert 0 < counts["lut"] < resources.XC6SLX45["lut"] // 10
    assert counts["bram18"] == 0 and counts["dsp"] == 0


def test_bench_json_is_flat_name_value_unit(tmp_path):
    figures = bench.collect(["sim.bench.bitplane"], resources=False, log=lambda *_: None)
    path = bench.write(figures, tmp_path / "bench.json")
    data = json.loads(path.read_text())
    assert "serialiser.pixels_per_cycle" in data
    for key, entry in data.items():
        assert set(entry) == {"value", "unit"}, key
        assert isinstance(entry["value"], (int, float)) and isinstance(entry["unit"], str)
