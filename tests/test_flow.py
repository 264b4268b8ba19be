"""The build flow: the Spartan-6 tree, Verilator lint, the resource report and bench.json."""

import json

import pytest
from amaranth import Module, unsigned
from amaranth.back import rtlil
from amaranth.lib import data, wiring
from amaranth.lib.wiring import In, Out

from flow import bench, resources, timing, verilog
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
    # the light gate out, on PMOD JB pin 8
    assert 'NET "light_gate_out_0__io" LOC=' in ucf
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
    # its network port: the PHY's pins, its receive clock constrained, the synchronisers ignored
    for name in ("rx_clk__io", "rx_data__io<7>", "rx_dv__io", "tx_data__io<7>", "tx_en__io", "gtx_clk__io"):
        assert f'NET "eth_gmii_0__{name}" LOC=' in ucf, name
    assert 'PERIOD "PRDgmii/rx_clk/i" 8.0 ns' in ucf and '"cdc_first_stages" TIG' in ucf
    # each output's buffer module holds its flip-flop, marked for the pad
    modules = {text.split("(")[0].strip(): text for text in (out / f"{top}.v").read_text().split("\nmodule ")[1:]}
    for buffer in [f"sync{k}" for k in range(BOARDS)] + ["camera"]:
        assert '(* IOB = "TRUE" *)' in modules[f"\\sync_master.{buffer}"], buffer
    assert not any("IOB" in text for name, text in modules.items() if "ready" in name or "switches" in name)


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


class _Groups(wiring.Component):
    """Four counters behind one array port: Amaranth names its elements ``frame[0]``..``frame[3]``,
    as ABC9 names the port's bits."""
    def __init__(self):
        super().__init__({"load": In(4), "step": In(8), "frame": Out(data.ArrayLayout(unsigned(8), 4))})

    def elaborate(self, platform):
        m = Module()
        for g in range(4):
            with m.If(self.load[g]):
                m.d.sync += self.frame[g].eq(self.frame[g] + self.step)
        return m


class _Sum(wiring.Component):
    def __init__(self):
        super().__init__({"load": In(4), "step": In(8), "total": Out(8)})

    def elaborate(self, platform):
        m = Module()
        m.submodules.groups = groups = _Groups()
        m.d.comb += [groups.load.eq(self.load), groups.step.eq(self.step),
                     self.total.eq(sum(groups.frame[g] for g in range(4)))]
        return m


def test_array_port_synthesises_in_hierarchy():
    """The sequencer's failure in Yosys, small: ABC9 put back a submodule whose array port's
    element names are also its bits' names (a duplicate wire) unless those names are dropped."""
    path = build_dir("test_flow", "synth") / "array_port.il"
    path.write_text(rtlil.convert(_Sum(), name="array_port", emit_src=False))
    counts = resources.count(resources.synthesise(path, "array_port", flatten=False))
    assert counts["ff"] == 4 * 8 and counts["lut"] > 0


def test_yosys_failure_names_its_error(tmp_path):
    bad = tmp_path / "broken.v"
    bad.write_text("module broken(input a, output b); missing m(.a(a), .b(b)); endmodule\n")
    with pytest.raises(RuntimeError, match="missing"):
        resources.synthesise(bad, "broken")
    with pytest.raises(RuntimeError, match="missing"):         # the timing report's synthesis too
        timing.netlist(bad.read_text(), "broken", workdir=tmp_path / "timing")


def test_board_figures_give_the_share_of_its_device():
    counts = {"lut": 9215, "ff": 0, "bram18": 134, "dsp": 18, "oserdes2": 72, "pll": 2, "bufpll": 2,
              "top": "projector_dlp9500", "device": "xc6slx150t"}
    block = {**counts, "device": None}
    out = resources.figures({"total_dlp9500": counts, "sequencer": block})
    assert out["res.total_dlp9500.lut_used"] == (10.0, "% of XC6SLX150T")
    assert out["res.total_dlp9500.bram18_used"][0] == 50.0
    assert out["res.total_dlp9500.oserdes2"] == (72, "OSERDES2")
    assert "res.sequencer.lut" in out and "res.sequencer.lut_used" not in out


def test_bench_json_is_flat_name_value_unit(tmp_path):
    figures = bench.collect(["sim.bench.bitplane_figures"], resources=False, log=lambda *_: None)
    path = bench.write(figures, tmp_path / "bench.json")
    data = json.loads(path.read_text())
    assert "serialiser.pixels_per_cycle" in data
    for key, entry in data.items():
        assert set(entry) == {"value", "unit", "source"}, key
        assert isinstance(entry["value"], (int, float)) and isinstance(entry["unit"], str)
