"""The logic-depth analysis (:mod:`flow.timing`) on a small design whose paths are known: a
register fed by the parity of 64 registers (a tree of LUTs), and the deepest path to it read back
cell by cell with the registers each cell reads."""

from amaranth import Module, Signal
from amaranth.back import verilog
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from flow import timing
from sim.harness.paths import build_dir


class Chain(wiring.Component):
    """``deep``: a parity of 64 registers (a tree of LUTs several levels deep); ``shallow``: one
    register's copy."""
    i: In(64)
    deep: Out(1)
    shallow: Out(1)

    def elaborate(self, platform):
        m = Module()
        regs = Signal(64)
        m.d.sync += [regs.eq(self.i), self.deep.eq(regs.xor()), self.shallow.eq(regs[0])]
        return m


def test_deepest_path_reads_the_registers_it_starts_from():
    text = verilog.convert(Chain(), name="chain", emit_src=False, strip_internal_attrs=True)
    module = timing.netlist(text, "chain", workdir=build_dir("timing", "test-chain"))
    (domain,) = timing.analyse(module).values()
    # a 64-input parity needs at least three levels of 6-input LUTs (6 * 6 = 36 < 64 inputs)
    assert domain["lut_levels_max"] >= 3
    name, steps = timing.deepest_path(module, "deep")
    assert name == "deep"
    assert steps[0][1] == "start" and steps[0][2][0].startswith("regs[")
    # one LUT level a step, from the start register to the last level
    assert [luts for luts, _kind, _read in steps] == list(range(len(steps)))
    assert steps[-1][0] == domain["lut_levels_max"]
    assert all(kind.startswith("LUT") for _luts, kind, _read in steps[1:])
    # the first level reads the start register among its named inputs
    assert steps[0][2][0] in steps[1][2]
    _name, shallow = timing.deepest_path(module, "shallow")
    assert shallow[-1][0] == 0
