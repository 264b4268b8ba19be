"""Logic depth between flip-flops, per clock domain, from Yosys ``synth_xilinx -family xc6s``.

Nothing here can run ISE's timing analysis, so this is the best evidence we can give without
it: the mapped netlist's deepest register-to-register paths, counted in the units a Spartan-6
path is made of, and an estimate of their delay in ns from the data sheet's figures.

* **LUT levels**: LUT1..LUT6 cells on the path (a MUXF7/MUXF8 sits in the same slice as the
  LUTs it joins and is not counted; a LUT-RAM read counts as a LUT).
* **Carry chain**: the longest CARRY4 chain on the path, in bits (4 per CARRY4), and how many
  separate chains the path goes through.
* **Delay estimate** (:func:`path_ns_estimate`): clock to out, a LUT delay and a net a level, the
  carry chain's bits, a net into the flip-flop and its setup, from ``spec.facts.SPARTAN6_PATH``
  (DS162's -3 figures and a routing allowance per net that is an assumption), against the domain's
  clock period (``timing.<domain>.period_ns``). A path's end takes the most LUT levels and the
  longest chain of any path into it, perhaps two different paths: the estimate is the larger.
  Not modelled: a block RAM's or DSP's clock to out (a path from one starts later than from a
  flip-flop), fanout, placement. ISE's timing report is the check this stands in for.

How the LUTs are mapped (:func:`netlist`): ``synth_xilinx`` as it is, up to its LUT mapping;
then each clock domain's logic is mapped on its own (the cones of its registers), so that the
mapper's area recovery does not stretch a path towards the slowest in the whole design, another
domain's. Each domain is mapped twice, and both are reported:

* **Yosys' delays** (the headline: ``timing.<domain>.lut_levels_max``, ``.registers_over_budget``,
  ``.path_ns_max_estimate``; ``python -m flow timing``): every LUT input given Yosys' own delay,
  its slowest input's, :data:`LUT_DELAY` = 642 ps, against its own carry chain delays. Yosys has
  no Spartan-6 delays and maps with Artix-7's; a 16-bit carry chain weighs more than a LUT level
  to it, so it may relax a LUT-only path by a level or two where a path with a chain is slower.
  This is the conservative measure, and the headline.
* **Uniform** (``timing.<domain>.lut_levels_max_uniform_mapping`` and the others with that
  suffix; ``--lut-delay 5000``): every LUT input :data:`UNIFORM_LUT_DELAY` = 5,000 ps, far above a
  carry chain's, so the mapper minimises LUT levels as the budget counts them (a 16-bit chain on
  top of them allowed). It says how deep the logic need be, where the headline says how deep a
  mapper left to its own delays made it; the two are kept side by side so that neither is read
  alone.

A path starts at a flip-flop output, a block RAM or DSP output, a shift-register LUT or a top
input, and ends at a flip-flop, block RAM, DSP or shift-register input, or at a LUT-RAM's write
side (data, write enable, write address: written on the clock edge); a LUT-RAM read is one LUT
level from its read address to its output. A path belongs to the clock domain of the cell it
ends at. The budget for 200 MHz on a -3 Spartan-6 that the ``dmd`` domain
is pipelined to: at most 4 LUT levels and one carry chain of at most 16 bits on any path.

``python -m flow timing`` prints the figures and the deepest paths of the projector's core in
the headline mapping, and the uniform mapping's figures after them (``--lut-delay PS``: that
mapping alone); ``--path NAME`` also prints the deepest path to a register, cell by cell, with
the named nets each cell reads (the LUTs' own names are the mapper's), to read it against the
source.
"""

import json
import re
from dataclasses import dataclass
from pathlib import Path

__all__ = ["Depth", "analyse", "deepest_path", "netlist", "netlists", "path_ns_estimate", "report", "figures",
           "BUDGET", "LUT_DELAY", "UNIFORM_LUT_DELAY", "main"]

#: The ``dmd`` domain's budget: LUT levels, carry bits, carry chains per path.
BUDGET = {"lut_levels_max": 4, "carry_max": 16, "carry_chains_max": 1}

_LUTS = {f"LUT{n}" for n in range(1, 7)} | {"LUT6_2", "INV"}
#: LUT-RAM: each read output depends, through one LUT level, on its own read address only; the
#: write side (data, write enable, write address) is sampled on the write clock like a
#: flip-flop's D input, so a path ends there.
_LUTRAM_READS = {
    **{kind: {f"DO{p}": f"ADDR{p}" for p in "ABCD"} for kind in ("RAM32M", "RAM64M")},
    **{kind: {"SPO": "A", "DPO": "DPRA"} for kind in ("RAM32X1D", "RAM64X1D", "RAM128X1D")},
    # (a RAM256X1S is four 64-deep LUTs and the slice's MUXF7/MUXF8: one LUT level, as a LUT7/8)
    **{kind: {"O": "A"} for kind in ("RAM32X1S", "RAM64X1S", "RAM128X1S", "RAM256X1S")},
}
#: LUT-RAM read addresses that are not its write address too: a path through one goes on through
#: the read (and is counted where it ends) and does not end at the LUT-RAM, whose write clock may
#: be another domain's.
_LUTRAM_READ_ONLY = {
    **{kind: {"ADDRA", "ADDRB", "ADDRC"} for kind in ("RAM32M", "RAM64M")},
    **{kind: {"DPRA"} for kind in ("RAM32X1D", "RAM64X1D", "RAM128X1D")},
}
_FREE = {"MUXF7", "MUXF8", "BUFG", "BUF", "IBUF", "OBUF", "VCC", "GND"}
#: Cells whose outputs are registered: a path ends at their inputs and starts at their outputs.
_SEQUENTIAL_PREFIXES = ("FD", "LD", "RAMB", "SRL", "DSP48A1_REGISTERED")
#: A DSP48A1 used without its pipeline registers is a combinational multiplier: counted as this
#: many LUT levels (about 4 ns on a -3 part).
_DSP_LEVELS = 3
_DSP_REGISTERS = ("A0REG", "A1REG", "B0REG", "B1REG", "CREG", "DREG", "MREG", "PREG")
#: Clock pins of the sequential cells.
_CLOCK_PINS = ("C", "CLK", "CLKA", "CLKB", "CLKAWRCLK", "CLKBRDCLK", "WCLK")


@dataclass
class Depth:
    """The deepest path found to one net: LUTs on it, the longest carry chain on it (bits),
    the carry chains it goes through, the bits of the chain it is in now (0: none), and where
    its deepest LUT path starts."""
    luts: int = 0
    carry: int = 0
    chains: int = 0
    run: int = 0
    start: str = ""
    via: int | None = None      # the input net of the deepest LUT path's last cell


#: Every LUT input's delay (ps) to the mapper in the headline mapping (why: the module's
#: docstring): Yosys' own, its slowest input's (Artix-7's, the only LUT delays it has); a 16-bit
#: carry chain (about 1 ns in Yosys' model) weighs more than a level.
LUT_DELAY = 642
#: Every LUT input's delay (ps) in the uniform mapping: a level outweighs a 16-bit carry chain
#: several times over, so the mapper minimises LUT levels as the budget counts them.
UNIFORM_LUT_DELAY = 5000
#: The ``gmii_rx`` domain's clock, the PHY's RX_CLK: 125 MHz at 1000 Mb/s (the platform's clock
#: constraint); the other domains' are the clock plan's (:mod:`gateware.platform.clocks`).
GMII_RX_HZ = 125e6


def _lut_library(delay):
    """``{inputs: (area, delay)}``: Yosys' areas; a LUT7/LUT8 is a LUT6 and the MUXF7/MUXF8
    after it, their delays as Yosys gives them."""
    return {1: (1, delay), 2: (2, delay), 3: (3, delay), 4: (3, delay), 5: (3, delay), 6: (5, delay),
            7: (10, delay + 223 + 174), 8: (20, delay + 223 + 104 + 192)}


#: Yosys' wire delay for its Xilinx mapping (``synth_xilinx.abc9.xc7.W``).
_WIRE_DELAY = 300
#: Where a path ends at a cell before LUT mapping: the inputs of its flip-flops, block RAMs, a
#: LUT-RAM's write side and a shift register's data (a cone is followed back no further).
_CONE_STOPS = ("-FDRE,FDSE,FDCE,FDPE[D,CE,R,S,CLR,PRE]:-RAMB16BWER,RAMB8BWER"
               ":-RAM32M,RAM64M[DIA,DIB,DIC,DID,WE]:-RAM32X1D,RAM64X1D,RAM128X1D,RAM32X1S,RAM64X1S,RAM128X1S"
               "[D,WE]:-SRLC32E,SRL16E[D,CE]")


def _clocks(verilog, top):
    """The clock inputs of ``top`` in Amaranth's names: ``clk`` and ``<domain>_clk``."""
    body = verilog[verilog.index(f"module {top}("):]
    body = body[:body.index("endmodule")]
    return [name for name in re.findall(r"^\s*input\s+(?:\[[^\]]*\]\s*)?(\w+)\s*;", body, re.M)
            if name == "clk" or name.endswith("_clk")]


def netlist(verilog, top, *, workdir, lut_delay=LUT_DELAY):
    """Synthesise ``verilog`` for XC6S: ``{clock net: flattened module's JSON netlist}``, one
    netlist per clock domain, every LUT input ``lut_delay`` ps to the mapper (:func:`netlists`)."""
    return netlists(verilog, top, workdir=workdir, lut_delays=(lut_delay,))[lut_delay]


def netlists(verilog, top, *, workdir, lut_delays=(LUT_DELAY, UNIFORM_LUT_DELAY)):
    """Synthesise ``verilog`` for XC6S: ``{lut delay: {clock net: flattened module's JSON
    netlist}}``, one netlist per clock domain and LUT delay, in one Yosys run.

    ``synth_xilinx -family xc6s`` runs once up to its LUT mapping; then each domain's logic (the
    cone of the registers on its clock, back to the registers it starts from) is mapped alone, as
    ``synth_xilinx`` maps it but with every LUT input the given delay (ps), once a delay. Mapped
    together, the mapper's area recovery would stretch every path up to the slowest in the netlist,
    whichever clock it is on; a mapper working to a period per clock does not."""
    from flow.resources import run_yosys
    workdir = Path(workdir)
    workdir.mkdir(parents=True, exist_ok=True)
    source = workdir / f"{top}.v"
    source.write_text(verilog)
    flags = f"-family xc6s -top {top} -flatten -noiopad -noclkbuf"
    clocks = _clocks(verilog, top)
    script = [f"read_verilog {source.name}", f"synth_xilinx {flags} -run :map_luts", "design -save premap"]
    outs = {}
    for lut_delay in dict.fromkeys(lut_delays):
        library = workdir / f"levels.{lut_delay}.lut"
        library.write_text("".join(f"{k} {area}.00 {delay}\n"
                                   for k, (area, delay) in _lut_library(lut_delay).items()))
        for clock in clocks:
            outs[lut_delay, clock] = workdir / f"{top}.{clock}.{lut_delay}ps.netlist.json"
            script += [
                "design -load premap",
                f"select -set ends w:{clock} %co1 w:{clock} %d",
                # (the domain's registers stay, though what reads them is not mapped here)
                "setattr -set keep 1 @ends",
                f"select -set cone @ends %ci1 %ci*:{_CONE_STOPS}",
                "delete c:* @cone %d",
                # ``synth_xilinx``'s map_luts, with the LUT library
                "opt_expr -mux_undef -noclkinv",
                "read_verilog -icells -lib -specify +/xilinx/abc9_model.v",
                f"abc9 -W {_WIRE_DELAY} -lut {library.name}",
                "clean",
                "xilinx_srl -fixed -minlen 3",
                "techmap -map +/xilinx/lut_map.v -map +/xilinx/cells_map.v -D LUT_WIDTH=6",
                "xilinx_dffopt",
                "opt_lut_ins -tech xilinx",
                f"synth_xilinx {flags} -run finalize:",
                f"write_json {outs[lut_delay, clock].name}",
            ]
    run_yosys("; ".join(script), top, workdir)
    out = {}
    for (lut_delay, clock), path in outs.items():
        out.setdefault(lut_delay, {})[clock] = json.loads(path.read_text())["modules"][top]
    return out


def _registered_dsp(cell):
    return cell["type"] == "DSP48A1" and any(int(str(cell["parameters"].get(p, "0")), 2) == 1
                                             for p in ("MREG", "PREG"))


def _sequential(kind):
    return kind.startswith(_SEQUENTIAL_PREFIXES)


def _depths(module):
    """Every net's :class:`Depth`, with the netlist's names, cells and drivers."""
    names = {}
    for name, net in module["netnames"].items():
        for bit in net["bits"]:
            if isinstance(bit, int) and (bit not in names or len(name) < len(names[bit])):
                names[bit] = name
    cells = module["cells"]
    drivers = {}
    for cname, cell in cells.items():
        for pin, direction in cell["port_directions"].items():
            if direction == "output":
                for bit in cell["connections"][pin]:
                    if isinstance(bit, int):
                        drivers[bit] = cname

    def inputs(cell):
        return [(pin, bit) for pin, d in cell["port_directions"].items()
                if d == "input" and pin not in _CLOCK_PINS for bit in cell["connections"][pin]]

    def reads(cell):
        """A LUT-RAM's read ports: ``{output pin: [its read address bits]}``."""
        ports = _LUTRAM_READS[cell["type"]]
        return {out: [bit for pin, bits in cell["connections"].items()
                      if pin.rstrip("0123456789") == addr for bit in bits]
                for out, addr in ports.items() if out in cell["connections"]}

    def comb_inputs(cell):
        """The inputs an output of a combinational cell depends on (a LUT-RAM's: its read
        addresses)."""
        if cell["type"] in _LUTRAM_READS:
            return [(out, bit) for out, bits in reads(cell).items() for bit in bits]
        return inputs(cell)

    # combinational cells in topological order
    for cell in cells.values():
        if _registered_dsp(cell):
            cell["type"] = "DSP48A1_REGISTERED"
    comb = [c for c, cell in cells.items() if not _sequential(cell["type"])]
    deps = {c: {drivers[b] for _, b in comb_inputs(cells[c]) if isinstance(b, int) and b in drivers
                and not _sequential(cells[drivers[b]]["type"])} for c in comb}
    users = {c: [] for c in comb}
    for c, ds in deps.items():
        for d in ds:
            users[d].append(c)
    waiting = {c: len(ds) for c, ds in deps.items()}
    order = [c for c in comb if waiting[c] == 0]
    for c in order:
        for u in users[c]:
            waiting[u] -= 1
            if waiting[u] == 0:
                order.append(u)
    if len(order) != len(comb):
        raise RuntimeError("combinational loop in the netlist")

    state = {}

    def of(bit):
        if isinstance(bit, int) and bit in state:
            return state[bit]
        return Depth(start=names.get(bit, "input") if isinstance(bit, int) else "constant")

    def settle(bits, out):
        for bit in bits:
            if isinstance(bit, int):
                state[bit] = out

    for cname in order:
        cell = cells[cname]
        kind = cell["type"]
        if kind in _LUTRAM_READS:
            for out_pin, addr in reads(cell).items():
                ds = [of(b) for b in addr]
                deepest = max(ds, key=lambda d: d.luts, default=Depth(start=cname))
                via = addr[ds.index(deepest)] if ds else None
                settle(cell["connections"][out_pin],
                       Depth(deepest.luts + 1, max((d.carry for d in ds), default=0),
                             max((d.chains for d in ds), default=0), 0, deepest.start, via))
            continue
        ins = [(pin, of(bit)) for pin, bit in inputs(cell)]
        deepest = max((d for _, d in ins), key=lambda d: d.luts, default=Depth(start=cname))
        via = max((bit for _, bit in inputs(cell) if isinstance(bit, int)), key=lambda b: of(b).luts, default=None)
        luts = deepest.luts + (1 if kind in _LUTS else _DSP_LEVELS if kind == "DSP48A1" else 0)
        carry = max((d.carry for _, d in ins), default=0)
        chains = max((d.chains for _, d in ins), default=0)
        run = 0
        if kind == "CARRY4":
            ci = [d for pin, d in ins if pin == "CI"]
            run = (ci[0].run if ci else 0) + 4
            carry = max(carry, run)
            chains = max([d.chains + 1 for pin, d in ins if pin != "CI"]
                         + [d.chains + (0 if d.run else 1) for pin, d in ins if pin == "CI"])
        out = Depth(luts, carry, chains, run, deepest.start, via)
        for pin, direction in cell["port_directions"].items():
            if direction == "output":
                settle(cell["connections"][pin], out)
    return of, names, cells, drivers, inputs


def _ends(cells, names, inputs, of):
    """Each path's end: ``(clock net, end name, input pin, its Depth)``, a path ending at a
    flip-flop, block RAM, DSP or shift register input, or at a LUT-RAM's write side (its
    read-only addresses not: those paths go on through the read)."""
    for cname, cell in cells.items():
        if not (_sequential(cell["type"]) or cell["type"] in _LUTRAM_READS):
            continue
        read_only = _LUTRAM_READ_ONLY.get(cell["type"], set())
        clocks = [cell["connections"][p][0] for p in _CLOCK_PINS if p in cell["connections"]]
        end = names.get(cell["connections"].get("Q", [None])[0], cname)
        for pin, bit in inputs(cell):
            if pin.rstrip("0123456789") not in read_only:
                yield (clocks[0] if clocks else None), end, bit, of(bit)


def analyse(module, *, keep=5):
    """Per clock domain (named after the net on the clock pins): ``{"lut_levels_max",
    "carry_max", "carry_chains_max", "paths", "over", "path_ns_max_estimate", "path_ns_deepest"}``,
    ``paths`` the ``keep`` deepest, deepest first, as ``(luts, carry bits, chains, start, end)``;
    ``over`` as :func:`over_budget`; the largest :func:`path_ns_estimate` of any path and that
    path."""
    of, names, cells, _drivers, inputs = _depths(module)
    domains = {}
    for clock, end, _bit, d in _ends(cells, names, inputs, of):
        domain = names.get(clock, "?") if clock is not None else "?"
        entry = domains.setdefault(domain, {"lut_levels_max": 0, "carry_max": 0, "carry_chains_max": 0,
                                            "paths": []})
        entry["lut_levels_max"] = max(entry["lut_levels_max"], d.luts)
        entry["carry_max"] = max(entry["carry_max"], d.carry)
        entry["carry_chains_max"] = max(entry["carry_chains_max"], d.chains)
        entry["paths"].append((d.luts, d.carry, d.chains, d.start, end))
    for entry in domains.values():
        entry["over"] = over_budget(entry["paths"])
        entry["path_ns_deepest"] = max(entry["paths"], key=lambda p: path_ns_estimate(p[0], p[1]))
        entry["path_ns_max_estimate"] = path_ns_estimate(*entry["path_ns_deepest"][:2])
        seen, paths = set(), []
        for path in sorted(entry["paths"], key=lambda p: (p[0], p[1], p[2]), reverse=True):
            if (path[3], path[4]) not in seen:
                seen.add((path[3], path[4]))
                paths.append(path)
            if len(paths) == keep:
                break
        entry["paths"] = paths
    return domains


def deepest_path(module, end):
    """The deepest path ending at a register whose name contains ``end``: ``(end name, steps)``,
    each step a combinational cell from the start on, as ``(LUT levels so far, cell type, the
    named nets it reads)`` (Yosys' own ``$`` nets left out: they name nothing in the source), so
    that a path through LUTs whose names the mapping lost can be read against the source."""
    of, names, cells, drivers, inputs = _depths(module)
    bit_names = {}
    for name, net in module["netnames"].items():
        if name.startswith("$"):
            continue
        for index, bit in enumerate(net["bits"]):
            if isinstance(bit, int) and (bit not in bit_names or len(name) < len(bit_names[bit])):
                bit_names[bit] = f"{name}[{index}]" if len(net["bits"]) > 1 else name
    found = [(d.luts, name, bit) for _clock, name, bit, d in _ends(cells, names, inputs, of) if end in name]
    if not found:
        raise ValueError(f"no register named like {end!r}")
    _luts, name, bit = max(found, key=lambda f: f[0])
    steps = []
    while isinstance(bit, int) and bit in drivers and not _sequential(cells[drivers[bit]]["type"]):
        cell = cells[drivers[bit]]
        read = sorted({bit_names[b] for _pin, b in inputs(cell) if b in bit_names})
        steps.append((of(bit).luts, cell["type"], read))
        bit = of(bit).via
    start = bit_names.get(bit, names.get(bit, "input")) if isinstance(bit, int) else "constant"
    return name, [(0, "start", [start])] + steps[::-1]


def _path_delays():
    """``spec.facts.SPARTAN6_PATH`` in ns."""
    from spec.facts import SPARTAN6_PATH
    return {key: fact.value * 1e9 for key, fact in SPARTAN6_PATH.items()}


def path_ns_estimate(luts, carry_bits, delays=None):
    """A register-to-register path's delay (ns) on a -3 Spartan-6, from its LUT levels and carry
    chain bits: clock to out, a net and a LUT a level, the chain a bit at a time (a CARRY4's CIN to
    COUT over its four bits), a net into the flip-flop and its setup::

        t_cko + luts * (t_route_net + t_ilo) + carry_bits * t_byp / 4 + t_route_net + max(t_as, t_dick)

    ``delays``: ``{name: ns}`` as ``spec.facts.SPARTAN6_PATH`` names them (its figures by default).
    The setup is the larger of the two (TAS, through the last LUT, counts that LUT a second time);
    every net gets the routing allowance, though a LUT's output into its own slice's flip-flop
    takes none: both on the side of a longer path."""
    d = _path_delays() if delays is None else delays
    net = d["t_route_net"]
    return (d["t_cko"] + luts * (net + d["t_ilo"]) + carry_bits * d["t_byp"] / 4
            + net + max(d["t_as"], d["t_dick"]))


def _within(path):
    luts, carry, chains = path[:3]
    return (luts <= BUDGET["lut_levels_max"] and carry <= BUDGET["carry_max"]
            and chains <= BUDGET["carry_chains_max"])


def over_budget(paths):
    """The registers with a path over :data:`BUDGET` ending at them, the bits of a vector (and
    registers that differ only in an index) taken together: ``[(name, paths over, deepest path)]``,
    deepest first."""
    groups = {}
    for path in paths:
        if _within(path):
            continue
        parts = path[4].split(".")
        name = ".".join(parts[:-1] + [parts[-1].rstrip("0123456789")])
        count, worst = groups.get(name, (0, path))
        groups[name] = (count + 1, max(worst, path, key=lambda p: p[:3]))
    return sorted(((name, count, worst) for name, (count, worst) in groups.items()),
                  key=lambda item: item[2][:3], reverse=True)


def _domain_of(net):
    """``dmd_clk`` -> ``dmd``; Amaranth names the ``sync`` domain's clock ``clk``."""
    return "sync" if net == "clk" else net[:-len("_clk")] if net.endswith("_clk") else net


def _periods_ns():
    """``{domain: clock period in ns}`` of the projector's domains."""
    from gateware.platform.clocks import Spartan6Clocks
    hz = {"gmii_rx": GMII_RX_HZ, **Spartan6Clocks.frequencies()}
    return {domain: 1e9 / f for domain, f in hz.items()}


def _synthesise(component=None, *, name="projector", workdir="build/timing", lut_delays=(LUT_DELAY,)):
    """The netlists of the projector's core (or ``component``), ``{lut delay: {clock net: module}}``."""
    from amaranth.back import verilog
    if component is None:
        from flow.blocks import core
        component = core()
    text = verilog.convert(component, name=name, emit_src=False, strip_internal_attrs=True)
    return netlists(text, name, workdir=workdir, lut_delays=lut_delays)


def _by_domain(netlists, periods=None):
    """Each domain's figures, from the netlist it was mapped in, with its clock period in ns
    (``period_ns``, None where ``periods``, by default the projector's, has none)."""
    periods = _periods_ns() if periods is None else periods
    out = {}
    for clock, module in netlists.items():
        entry = analyse(module).get(clock)
        if entry is not None:
            domain = _domain_of(clock)
            entry["period_ns"] = periods.get(domain)
            out[domain] = entry
    return out


def report(component=None, *, name="projector", workdir="build/timing"):
    """Synthesise the projector's core (or ``component``) and analyse it in both mappings (the
    module's docstring): ``{domain: ...}`` of the headline mapping, Yosys' delays, each with the
    uniform mapping's under ``"uniform_mapping"``."""
    mapped = _synthesise(component, name=name, workdir=workdir, lut_delays=(LUT_DELAY, UNIFORM_LUT_DELAY))
    result = _by_domain(mapped[LUT_DELAY])
    for domain, entry in _by_domain(mapped[UNIFORM_LUT_DELAY]).items():
        if domain in result:
            result[domain]["uniform_mapping"] = entry
    return result


_FIGURES = (("lut_levels_max", "LUT levels"), ("carry_max", "bits"), ("carry_chains_max", "chains"))


def figures(result):
    """``{name: (value, unit)}``: each domain's headline figures (Yosys' delays),
    ``timing.<domain>.lut_levels_max``, ``.carry_max``, ``.carry_chains_max``,
    ``.registers_over_budget``, ``.path_ns_max_estimate`` and ``.period_ns``; the same figures of
    the uniform mapping, where ``result`` has it, with ``_uniform_mapping`` after the name."""
    out = {}
    for domain, entry in result.items():
        mappings = [("", entry)]
        if "uniform_mapping" in entry:
            mappings.append(("_uniform_mapping", entry["uniform_mapping"]))
        for suffix, figures_of in mappings:
            for key, unit in _FIGURES:
                out[f"timing.{domain}.{key}{suffix}"] = (figures_of[key], unit)
            out[f"timing.{domain}.registers_over_budget{suffix}"] = (len(figures_of["over"]), "registers")
            out[f"timing.{domain}.path_ns_max_estimate{suffix}"] = (round(figures_of["path_ns_max_estimate"], 3),
                                                                    "ns")
        if entry.get("period_ns") is not None:
            out[f"timing.{domain}.period_ns"] = (round(entry["period_ns"], 3), "ns")
    return out


def _summary(domain, entry):
    period = entry.get("period_ns")
    against = f" (period {period:.2f} ns)" if period is not None else ""
    return (f"{domain}: {entry['lut_levels_max']} LUT levels, carry chains up to {entry['carry_max']} bits, "
            f"{entry['carry_chains_max']} chain(s) on a path; {len(entry['over'])} register(s) over the budget; "
            f"path estimate up to {entry['path_ns_max_estimate']:.2f} ns{against}")


def print_report(result, *, over=()):
    """The figures and deepest paths of each domain; for the domains in ``over``, every register
    a path over the budget ends at."""
    for domain in sorted(result):
        entry = result[domain]
        budget = "  (budget: 4 LUT levels, one carry chain of 16 bits)" if domain == "dmd" else ""
        print(_summary(domain, entry) + budget)
        for luts, carry, chains, start, end in entry["paths"]:
            print(f"    {luts} LUT, carry {carry} bits ({chains} chain(s)), ~{path_ns_estimate(luts, carry):.2f} ns: "
                  f"{start} -> {end}")
        luts, carry, chains, start, end = entry["path_ns_deepest"]
        print(f"  longest estimate: {luts} LUT, carry {carry} bits, ~{entry['path_ns_max_estimate']:.2f} ns: "
              f"{start} -> {end}")
        if domain in over:
            print(f"  registers with a path over the budget: {len(entry['over'])}")
            for name, count, (luts, carry, chains, start, _end) in entry["over"]:
                print(f"    {luts:3d} LUT {carry:3d} bits {chains} chain(s) {count:5d} path(s): {name} <- {start}")


def _estimate_basis():
    from spec.facts import SPARTAN6_PATH
    return ", ".join(f"{key} {fact.value * 1e9:g} ns" + (" (assumed)" if fact.confidence == "assumption" else "")
                     for key, fact in SPARTAN6_PATH.items())


def main(*, block=None, over=(), path=(), lut_delay=LUT_DELAY):
    """``block``: one block of :data:`flow.blocks.BLOCKS` instead of the projector's core;
    ``path``: print the deepest path to each register named like these, step by step;
    ``lut_delay``: the headline mapping's (:data:`LUT_DELAY`, and the uniform mapping's figures
    after it), or another delay's alone (:data:`UNIFORM_LUT_DELAY`: the uniform mapping)."""
    delays = (lut_delay, UNIFORM_LUT_DELAY) if lut_delay == LUT_DELAY else (lut_delay,)
    if block is None:
        mapped = _synthesise(lut_delays=delays)
    else:
        from flow.blocks import BLOCKS
        mapped = _synthesise(BLOCKS[block](), name=block, workdir=f"build/timing/{block}", lut_delays=delays)
    kind = ("Yosys' delays, the headline" if lut_delay == LUT_DELAY else
            "uniform" if lut_delay == UNIFORM_LUT_DELAY else "given")
    print(f"mapping: every LUT input {lut_delay} ps ({kind})")
    print(f"path estimate (-3): {_estimate_basis()}")
    print_report(_by_domain(mapped[lut_delay]), over=over)
    if len(delays) > 1:
        print(f"uniform mapping, every LUT input {UNIFORM_LUT_DELAY} ps (levels as the budget counts them):")
        uniform = _by_domain(mapped[UNIFORM_LUT_DELAY])
        for domain in sorted(uniform):
            print("  " + _summary(domain, uniform[domain]))
    netlists = mapped[lut_delay]
    for end in path:
        # (a register of another domain is in a netlist too, where its cone is not mapped)
        found = []
        for module in netlists.values():
            try:
                found.append(deepest_path(module, end))
            except ValueError:
                pass
        if not found:
            raise ValueError(f"no register named like {end!r}")
        name, steps = max(found, key=lambda f: f[1][-1][0])
        print(f"deepest path to {name}: {steps[-1][0]} LUT levels")
        for luts, kind, read in steps:
            print(f"  {luts:3d} {kind:8} {', '.join(read)}")
    return 0
