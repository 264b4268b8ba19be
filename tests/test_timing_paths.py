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


def test_path_estimate_is_the_sum_of_its_parts():
    # made-up delays (ns), each a different power of ten, so that every term shows in the sum
    delays = {"t_cko": 1, "t_ilo": 10, "t_route_net": 100, "t_byp": 4000, "t_as": 0.5, "t_dick": 0.25}
    # clock to out + 2 levels of (net + LUT) + 8 carry bits at a quarter of a CARRY4 + net in + setup
    assert timing.path_ns_estimate(2, 8, delays) == 1 + 2 * 110 + 8 * 1000 + 100 + 0.5
    # the facts' figures, by default: the data sheet's and the routing allowance
    from spec.facts import SPARTAN6_PATH
    ns = {key: fact.value * 1e9 for key, fact in SPARTAN6_PATH.items()}
    expected = (ns["t_cko"] + 4 * (ns["t_route_net"] + ns["t_ilo"]) + 16 * ns["t_byp"] / 4
                + ns["t_route_net"] + max(ns["t_as"], ns["t_dick"]))
    assert abs(timing.path_ns_estimate(4, 16) - expected) < 1e-9
    assert SPARTAN6_PATH["t_route_net"].confidence == "assumption"


def _lut_chain(levels):
    """A hand-made netlist: a flip-flop, ``levels`` LUT1s in series, a flip-flop, on ``clk``."""
    def cell(kind, ins, outs):
        return {"type": kind, "parameters": {},
                "port_directions": {**{p: "input" for p in ins}, **{p: "output" for p in outs}},
                "connections": {**ins, **outs}}
    clk, first = 2, 3
    cells = {"src": cell("FDRE", {"C": [clk], "D": [10]}, {"Q": [first]}),
             "dst": cell("FDRE", {"C": [clk], "D": [first + levels]}, {"Q": [11]})}
    for level in range(levels):
        cells[f"lut{level}"] = cell("LUT1", {"I0": [first + level]}, {"O": [first + level + 1]})
    return {"cells": cells, "netnames": {"clk": {"bits": [clk]}, "a": {"bits": [first]}, "b": {"bits": [11]},
                                         "d": {"bits": [10]}}}


def test_analyse_gives_the_deepest_paths_estimate():
    (domain,) = timing.analyse(_lut_chain(3)).values()
    assert domain["lut_levels_max"] == 3
    assert domain["path_ns_max_estimate"] == timing.path_ns_estimate(3, 0)
    assert domain["path_ns_deepest"][:2] == (3, 0)


def test_figures_name_both_mappings():
    def entry(levels, ns, over):
        return {"lut_levels_max": levels, "carry_max": 16, "carry_chains_max": 1, "over": [None] * over,
                "path_ns_max_estimate": ns, "period_ns": 5.0}
    result = {"dmd": {**entry(6, 5.4, 30), "uniform_mapping": entry(4, 4.1, 0)}}
    out = timing.figures(result)
    # the headline is Yosys' delays' mapping; the uniform one beside it, named so
    assert out["timing.dmd.lut_levels_max"] == (6, "LUT levels")
    assert out["timing.dmd.lut_levels_max_uniform_mapping"] == (4, "LUT levels")
    assert out["timing.dmd.registers_over_budget"] == (30, "registers")
    assert out["timing.dmd.registers_over_budget_uniform_mapping"] == (0, "registers")
    assert out["timing.dmd.path_ns_max_estimate"] == (5.4, "ns")
    assert out["timing.dmd.path_ns_max_estimate_uniform_mapping"] == (4.1, "ns")
    assert out["timing.dmd.period_ns"] == (5.0, "ns")
    for key in ("carry_max", "carry_chains_max"):
        assert f"timing.dmd.{key}" in out and f"timing.dmd.{key}_uniform_mapping" in out
