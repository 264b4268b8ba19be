"""The logic-depth analysis (:mod:`flow.timing`) on a small design whose paths are known: a
register fed by the parity of 64 registers (a tree of LUTs), and the deepest path to it read back
cell by cell with the registers each cell reads."""

from amaranth import ClockDomain, Module, Signal
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
    (module,) = timing.netlist(text, "chain", workdir=build_dir("timing", "test-chain")).values()
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


def _two_domains():
    """A parity of 64 registers in ``sync`` (3 levels at least) and an AND of 12 registers in
    ``fast`` (2 LUT6 levels), each domain's clock a port."""
    m = Module()
    m.domains.sync, m.domains.fast = sync, fast = ClockDomain("sync"), ClockDomain("fast")
    i, deep, wide = Signal(64), Signal(), Signal()
    regs, ands = Signal(64), Signal(12)
    m.d.sync += [regs.eq(i), deep.eq(regs.xor())]
    m.d.fast += [ands.eq(i[:12]), wide.eq(ands.all())]
    return verilog.convert(m, name="two", ports=[sync.clk, sync.rst, fast.clk, fast.rst, i, deep, wide],
                           emit_src=False, strip_internal_attrs=True)


def test_each_domain_is_mapped_on_its_own():
    netlists = timing.netlist(_two_domains(), "two", workdir=build_dir("timing", "test-two"))
    assert sorted(netlists) == ["clk", "fast_clk"]
    result = timing._by_domain(netlists)
    assert result["sync"]["lut_levels_max"] >= 3
    # the AND's own depth, not stretched towards the parity's
    assert result["fast"]["lut_levels_max"] == 2
    # the parity's LUTs are not in the fast domain's netlist (the AND's three are), nor the AND's
    # in the sync domain's
    luts = {clock: sum(cell["type"].startswith("LUT") for cell in module["cells"].values())
            for clock, module in netlists.items()}
    assert luts["fast_clk"] == 3 and luts["clk"] >= 13
