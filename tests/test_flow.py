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
    # a tiled display's board: the sync master's pulse in, the ready line back
    assert 'NET "sync_in_0__io" LOC=' in ucf and 'NET "ready_out_0__io" LOC=' in ucf
    v = (out / f"{top}.v").read_text()
    for primitive in ("PLL_BASE", "BUFG", "ODDR2", "OBUFTDS"):
        assert primitive in v, primitive
    # the top lints, the primitives and the memory controller declared as black boxes
    ok, messages = verilog.lint_top(out / f"{top}.v", top, verilog.blackboxes("atlys"), workdir=out.parent / "lint")
    assert ok, messages


def test_sync_master_tree_drives_every_board_from_a_pad_flip_flop():
    """The sync master's own build: a sync line per board and the camera trigger, each from a
    flip-flop ISE must pack into its pad (the pulses leave within the pads' skew)."""
    from gateware.top.sync_master import BOARDS
    out = build_dir("test_flow", "sync_master")
    top = verilog.emit_sync_master(out)
    ucf = (out / f"{top}.ucf").read_text()
    outputs = [f"board_sync_{k}__io" for k in range(BOARDS)] + ["camera_trigger_out_0__io"]
    for name in outputs + [f"board_ready_{k}__io" for k in range(BOARDS)] + ["frame_trigger_in_0__io"]:
        assert f'NET "{name}" LOC=' in ucf, name
    for name in outputs:
        assert f'NET "{name}" SLEW=FAST;' in ucf, name
    # each output's buffer module holds its flip-flop, marked for the pad
    modules = {text.split("(")[0].strip(): text for text in (out / f"{top}.v").read_text().split("\nmodule ")[1:]}
    for buffer in [f"sync{k}" for k in range(BOARDS)] + ["camera"]:
        assert '(* IOB = "TRUE" *)' in modules[f"\\sync_master.{buffer}"], buffer
    assert not any("IOB" in text for name, text in modules.items() if "ready" in name or "switches" in name)


#: The four-bus core is linted by ``make verilog``, not here: its Verilog takes 40 s to write, and
#: its parts are linted here (the four-bus sequencer) or built by Verilator (the core's blocks).
SUITE_LINTED = sorted(set(BLOCKS) - {"core_dlp9500"})


@pytest.mark.parametrize("name", SUITE_LINTED)
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
