"""The endpoint's reference model (:mod:`sim.models.net_model`) is an oracle apart from the
gateware: it imports no gateware and none of the checks the parser is built from, and its
register-set rule, written from ``docs/protocol.md``, agrees with
:func:`spec.records.register_faults` (the parser's) on random register sets near every boundary the
page names. Two rules written apart that agree are what makes the fuzz tests' verdicts worth
having."""

import ast
import inspect
import random
from pathlib import Path

from hypothesis import given, settings
from hypothesis import strategies as st

from sim.models import net_model as net
from sim.models.endpoint_traffic import BAD_REGISTERS, GOOD_WIRE
from spec import records
from spec.facts import DMDS, TEST_DMD
from spec.registers import lead_cycles
from spec.schedule import LIGHT_FALL, MIRRORS_SETTLED, row_cycles

SOURCE = Path(net.__file__)
#: The spec modules the model may take tables and the DMD's numbers from.
SHARED = {"spec", "spec.records", "spec.wire", "spec.facts"}
#: Each field of the sequencer record and its width on the wire.
WIDTHS = dict(records.SEQUENCER)
#: DMDs and DCLK beats per cycle the rules are compared on.
GEOMETRIES = [(dmd, beats) for dmd in DMDS.values() for beats in (1, 2) if dmd.dclk_per_row % beats == 0]
PLANES, GROUPS, OFFSET_BITS = 8, 16, 24
#: The light times' entries' width.
LIGHT_BITS = WIDTHS["light_times"] // PLANES


def imported(tree):
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            yield from (alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            yield node.module
            yield from (f"{node.module}.{alias.name}" for alias in node.names)


def test_model_shares_no_rule_with_the_parser():
    tree = ast.parse(SOURCE.read_text())
    modules = set(imported(tree))
    assert not {name for name in modules if name.split(".")[0] == "gateware"}
    assert {name for name in modules if name.split(".")[0] == "spec"} <= SHARED | {
        f"spec.records.{name}" for name in dir(records) if not inspect.isfunction(getattr(records, name))}
    names = {node.id for node in ast.walk(tree) if isinstance(node, ast.Name)}
    attributes = {node.attr for node in ast.walk(tree) if isinstance(node, ast.Attribute)}
    assert "register_faults" not in names | attributes | modules
    # of the records module, tables and constants only: no function that decides anything
    taken = {node.attr for node in ast.walk(tree) if isinstance(node, ast.Attribute)
             and isinstance(node.value, ast.Name) and node.value.id == "records"}
    assert not {name for name in taken if inspect.isfunction(getattr(records, name))}


def parser_refuses(registers, dmd, beats):
    return any(records.register_faults(registers, dmd, beats).values())


def even(value):
    return value + value % 2


def packed(entries, width):
    return sum(entry << width * i for i, entry in enumerate(entries))


def group_terms(registers, dmd, beats):
    """(blocks of a group of the set's reset mode, its reload: ``t_rst + t_settle``, then its rows
    at ``row_period``, the last a row cycle)."""
    group = min(dmd.blocks, (dmd.blocks, 4, 2, 1)[registers["reset_mode"]] if registers["reset_mode"] < 4 else 0)
    rows = max(0, group * dmd.rows_per_block - 1)
    return group, registers["t_rst"] + registers["t_settle"] + rows * registers["row_period"] + row_cycles(dmd, beats)


@st.composite
def taken_sets(draw, geometry):
    """A register set the sequencer takes on ``geometry``, drawn field by field from the page's
    bounds (the draws themselves are held to :func:`spec.records.register_faults` below). The
    bulky parts (the group tables and offsets, the fields no rule bounds) come from one drawn
    seed, so that an example is quick to draw."""
    dmd, beats = geometry
    rng = random.Random(draw(st.integers(0, (1 << 32) - 1)))
    row_cycle = row_cycles(dmd, beats)
    clear = dmd.clear_row_cycles * row_cycle
    shortest = max(clear, 4)
    lead = lead_cycles(row_cycle, dmd.clear_row_cycles)
    small = st.integers(0, 1000)
    out = {name: rng.getrandbits(width) for name, width in WIDTHS.items()}
    for name, largest in {"reset_mode": 3, "order": 3, "trigger": 3, "anchor": 7}.items():
        out[name] = draw(st.integers(0, largest))
    for name in ("chain", "strict_rst", "source", "ns_flip", "park", "trigger_hold"):
        out[name] = draw(st.integers(0, 1))
    gated = draw(st.booleans())
    if gated:
        out["reset_mode"] = 0            # (gating only in the global mode)
    out["t_rst"], out["t_settle"] = draw(small), draw(st.integers(3, 1000))
    out["row_period"] = draw(st.integers(row_cycle, 255))
    group, reload = group_terms(out, dmd, beats)
    out["lsb"] = even(out["t_rst"] + out["t_settle"] + group * even(clear) + draw(small))
    out["hide"] = draw(st.one_of(st.integers(reload, (1 << WIDTHS["hide"]) - 1),
                                 st.integers(out["lsb"] * 128 + 1, (1 << WIDTHS["hide"]) - 1)))
    out["dark_gap"] = even(draw(st.integers(reload, (1 << WIDTHS["dark_gap"]) - 2)))
    out["stagger"] = draw(st.one_of(st.just(0), st.integers(shortest, 10_000).map(even)))
    out["period"] = out["lsb"] + draw(small)
    out["order_table"] = packed(draw(st.permutations(range(PLANES))), 3)
    out["group_tables"] = packed([e for _ in range(GROUPS) for e in rng.sample(range(PLANES), PLANES)], 3)
    first = draw(st.one_of(st.just(0), st.integers(lead, 10_000).map(even)))
    offsets = [first] + [rng.choice([first, even(rng.randint(max(first, shortest), 20_000))])
                         for _ in range(GROUPS - 1)]
    out["group_offsets"] = packed(offsets, OFFSET_BITS)
    out["gated_time"] = even(out["gated_time"] % (1 << WIDTHS["gated_time"] - 1))
    if gated:
        # every plane gated: the light inside each plane, behind the mirrors
        out["gated_planes"] = 255
        out["light_lead"] = draw(st.integers(MIRRORS_SETTLED, 5000))
        light = [rng.randint(0, 2000) for _ in range(PLANES)]
        out["light_times"] = packed(light, LIGHT_BITS)
        out["gated_time"] = even(max(reload, out["light_lead"] + max(light) + LIGHT_FALL,
                                     out["t_rst"] + out["t_settle"] + group * even(clear)) + draw(small))
    else:
        out["gated_planes"] = 0
    return out


@st.composite
def near_boundaries(draw):
    """A geometry and a register set the sequencer takes there, then one to three fields moved,
    each to a value any width allows, a small one, or one near a bound the page names."""
    geometry = draw(st.sampled_from(GEOMETRIES))
    dmd, beats = geometry
    registers = draw(taken_sets(geometry))
    row_cycle = row_cycles(dmd, beats)
    clear = dmd.clear_row_cycles * row_cycle
    group, reload = group_terms(registers, dmd, beats)
    bounds = [row_cycle, clear, 4, max(clear, 4), lead_cycles(row_cycle, dmd.clear_row_cycles),
              registers["t_rst"] + registers["t_settle"] + clear,
              registers["t_rst"] + registers["t_settle"] + group * even(clear), registers["lsb"], reload,
              registers["lsb"] * 128, registers["hide"], MIRRORS_SETTLED, registers["gated_time"]]
    near = st.tuples(st.sampled_from(bounds), st.integers(-3, 3)).map(lambda b: max(0, sum(b)))
    for _ in range(draw(st.integers(1, 3))):
        name = draw(st.sampled_from(sorted(WIDTHS)))
        width = WIDTHS[name]
        value = draw(st.one_of(st.integers(0, (1 << width) - 1), st.integers(0, 9), near))
        if name == "group_offsets":
            # one group's offset moved, in any order (an odd one is refused in every order)
            mask = (1 << OFFSET_BITS) - 1
            offsets = [registers[name] >> OFFSET_BITS * g & mask for g in range(GROUPS)]
            offsets[draw(st.one_of(st.just(0), st.integers(0, GROUPS - 1)))] = value & mask
            registers[name] = packed(offsets, OFFSET_BITS)
            registers["order"] = draw(st.sampled_from([registers["order"], 3]))
        elif name == "light_times":
            # one gated plane's light moved near the end of its plane
            e, mask = draw(st.integers(0, PLANES - 1)), (1 << LIGHT_BITS) - 1
            light = [registers[name] >> LIGHT_BITS * k & mask for k in range(PLANES)]
            end = registers["gated_time"] - registers["light_lead"] - LIGHT_FALL
            light[e] = max(0, end + draw(st.integers(-3, 3))) & mask
            registers[name] = packed(light, LIGHT_BITS)
        elif name in ("order_table", "group_tables"):
            # one entry of one table changed
            j = draw(st.integers(0, width // 3 - 1))
            registers[name] = registers[name] & ~(7 << 3 * j) | draw(st.integers(0, 7)) << 3 * j
            registers["order"] = draw(st.sampled_from([registers["order"], 2 if name == "order_table" else 3]))
        else:
            registers[name] = value & ((1 << width) - 1)
    return registers, geometry


@st.composite
def offsets_near_boundaries(draw):
    """A geometry and a set it takes, then in the order by group every offset moved near the
    bounds the page names for them (a block clear, 4 cycles, group 0's lead), so that each bound
    decides alone at times."""
    geometry = draw(st.sampled_from(GEOMETRIES))
    dmd, beats = geometry
    registers = draw(taken_sets(geometry))
    row_cycle = row_cycles(dmd, beats)
    bounds = [0, row_cycle, dmd.clear_row_cycles * row_cycle, 4, lead_cycles(row_cycle, dmd.clear_row_cycles)]
    near = st.tuples(st.sampled_from(bounds), st.integers(-3, 3)).map(lambda b: max(0, sum(b)))
    first = draw(near)
    rng = random.Random(draw(st.integers(0, (1 << 32) - 1)))
    offsets = [first] + [first + 2 * rng.randint(0, 3) for _ in range(GROUPS - 1)]
    for _ in range(draw(st.integers(0, 2))):
        offsets[draw(st.integers(1, GROUPS - 1))] = draw(st.one_of(st.just(0), near))
    return {**registers, "order": 3, "group_offsets": packed(offsets, OFFSET_BITS)}, geometry


@settings(max_examples=200, deadline=None)
@given(st.sampled_from(GEOMETRIES).flatmap(lambda geometry: st.tuples(taken_sets(geometry), st.just(geometry))))
def test_drawn_sets_are_taken(case):
    registers, (dmd, beats) = case
    assert not parser_refuses(registers, dmd, beats)
    assert net.sequencer_refusals(registers, dmd, beats) == []


@settings(max_examples=600, deadline=None)
@given(st.one_of(near_boundaries(), offsets_near_boundaries()))
def test_model_rule_agrees_with_the_parsers(case):
    registers, (dmd, beats) = case
    refusals = net.sequencer_refusals(registers, dmd, beats)
    assert bool(refusals) == parser_refuses(registers, dmd, beats), refusals


def test_model_refuses_the_endpoint_tests_bad_sets():
    assert net.sequencer_refusals(GOOD_WIRE, TEST_DMD) == []
    for name, changes in BAD_REGISTERS.items():
        assert net.sequencer_refusals({**GOOD_WIRE, **changes}, TEST_DMD), name
