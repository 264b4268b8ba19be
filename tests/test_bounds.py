"""The bounds past one DMD (:mod:`spec.bounds`) against the schedule model: no plan the planner,
the plan finder or the ceiling's search makes is faster than the one-DMD bound; the shipped plan
comes close to it; a gated plane's time is exactly what the schedule model needs for a binary
pattern in global reset; the two-DMD bounds are the one-DMD bounds at the larger half; and the
docs' table says what binds as :mod:`spec.bounds` does."""

import math
import re
from dataclasses import replace
from pathlib import Path

import pytest

from spec import bounds, schedule
from spec.ceiling import ceiling_of_mode
from spec.facts import DMDS, LIGHT, TEST_DMD4_400, TEST_DMD_400
from spec.plan_search import find
from spec.registers import ResetMode
from spec.schedule import Frame

ROOT = Path(__file__).resolve().parents[1]
DCLK = 400e6
XGA = DMDS["dlp7000"]
#: The memory's read rate the figures take (sim.rigs.fast_system_rig.read_rate: 0.779 words a
#: cycle); here a rounder one of the same pace, 22 cycles a DLP7000 row.
MEMORY_WORDS = 0.75


def _paces(dmd, words):
    """The bound's terms at the row period the planner takes for ``words`` a cycle."""
    period = schedule.plan(dmd, DCLK, depth=1, chain=True, words_per_cycle=words).params.row_period
    return bounds.Paces.of(dmd, DCLK, period), period


@pytest.mark.parametrize("words", [2.0, MEMORY_WORDS], ids=["bus", "memory"])
def test_no_global_plan_beats_the_one_dmd_bound(words):
    """Triggered global plans at every depth to 8, chained ones at 1 bit, the ceiling's search
    (its loads at the row cycle: the bus's pace) at every depth."""
    paces, _ = _paces(XGA, words)
    for depth in range(1, 9) if words == 2.0 else (1, 5, 8):
        bound = bounds.one(paces, depth).frame_cycles
        assert schedule.plan(XGA, DCLK, depth=depth, words_per_cycle=words).frame_cycles >= bound
        bus = bounds.one(bounds.Paces.of(XGA, DCLK), depth).frame_cycles
        assert ceiling_of_mode(XGA, DCLK, ResetMode.GLOBAL, depth=depth).frame_cycles >= bus
    chained = schedule.plan(XGA, DCLK, depth=1, chain=True, words_per_cycle=words)
    assert chained.frame_cycles >= bounds.one(paces, 1).frame_cycles


@pytest.mark.parametrize("depth", [1, 4, 8])
def test_no_plan_the_finder_makes_beats_the_one_dmd_bound(depth):
    """Every reset mode and plane order on the small DMD."""
    paces, _ = _paces(TEST_DMD_400, MEMORY_WORDS)
    found = find(TEST_DMD_400, DCLK, depth=depth, words_per_cycle=MEMORY_WORDS, workers=1, hides=False)
    assert found.best.plan.frame_cycles >= bounds.one(paces, depth).frame_cycles
    if depth == 1:
        chained = [schedule.plan(TEST_DMD_400, DCLK, depth=1, chain=True, reset_mode=mode,
                                 words_per_cycle=MEMORY_WORDS) for mode in ResetMode]
        assert min(p.frame_cycles for p in chained) >= bounds.one(paces, 1).frame_cycles


def test_the_shipped_plan_is_under_the_bound_and_within_ten_percent():
    from sim.rigs import xga_run
    shipped = xga_run.plan(DCLK)
    bound = bounds.one(bounds.Paces.of(XGA, DCLK, shipped.params.row_period), 8)
    assert 0.88 * bound.rate_hz <= shipped.rate_hz <= bound.rate_hz
    assert bound.binds == "lsb"


@pytest.mark.parametrize("dmd", [XGA, TEST_DMD4_400], ids=lambda d: d.name.split()[0])
@pytest.mark.parametrize("words", [None, MEMORY_WORDS], ids=["bus", "memory"])
def test_a_gated_plane_is_what_a_binary_pattern_needs(dmd, words):
    """The schedule model plays chained 1-bit global frames at ``T`` with the facts table's
    RST_ACTIVE, and a pulse comes late two cycles shorter; the planner, with its margins, needs
    no less."""
    words = words or schedule.row_rate_words(dmd, DCLK)
    paces, _ = _paces(dmd, words)
    T, binds = bounds.plane_time(paces, 1)
    assert binds == "reload"
    plan = schedule.plan(dmd, DCLK, depth=1, chain=True, words_per_cycle=words)
    assert plan.frame_cycles >= T
    facts = replace(plan.params, t_rst=paces.t_rst, hide=0)
    assert schedule.on_time(dmd, replace(facts, lsb=T), Frame(0, 1))
    assert schedule.frame_period(dmd, replace(facts, lsb=T), Frame(0, 1)) == T
    assert not schedule.on_time(dmd, replace(facts, lsb=T - 2), Frame(0, 1))


def test_a_gated_frame_fits_its_light_in_its_planes():
    """Every plane's light, ``lsb << e``, starts after the lead and ends a source edge before
    the next pulse; the LSB is the shortest pulse asked for at least."""
    edge = math.ceil(max(LIGHT["t_rise"].value, LIGHT["t_fall"].value) * schedule.FABRIC_HZ - 1e-9)
    for dmd in (XGA, DMDS["dlp9500"]):
        for period in (None, 22, 42):
            paces = bounds.Paces.of(dmd, DCLK, period)
            for depth in bounds.DEPTHS:
                for lead in bounds.LEADS:
                    for shortest, least in (("cycle", 1), ("edges", 2 * edge)):
                        b = bounds.gated(paces, depth, lead, shortest)
                        T = b.frame_cycles // depth
                        assert T - bounds.gate_lead(lead) - (b.lsb << (depth - 1)) >= edge
                        assert b.lsb >= least
                        assert T >= bounds.plane_time(paces, 1)[0]


@pytest.mark.parametrize("period", [None, 22])
def test_two_dmds_are_one_dmd_at_the_larger_half(period):
    paces = bounds.Paces.of(XGA, DCLK, period)
    for depth in bounds.DEPTHS:
        for scheme, single in (("dual", bounds.one), ("dual_gated", bounds.gated)):
            b = bounds.SCHEMES[scheme](paces, depth)
            assert b.frame_cycles == single(paces, max(b.k, depth - b.k)).frame_cycles
            assert all(b.frame_cycles <= single(paces, max(k, depth - k)).frame_cycles for k in range(depth + 1))


@pytest.mark.parametrize("period", [None, 22, 42])
def test_every_bound_is_slower_with_more_bits(period):
    for dmd in (XGA, DMDS["dlp9500"]):
        paces = bounds.Paces.of(dmd, DCLK, period)
        for fn in bounds.SCHEMES.values():
            frames = [fn(paces, depth).frame_cycles for depth in bounds.DEPTHS]
            assert frames == sorted(frames)
        # and each scheme no slower than one DMD from 8 bits on
        for depth in range(8, 17):
            assert all(fn(paces, depth).frame_cycles <= bounds.one(paces, depth).frame_cycles
                       for fn in bounds.SCHEMES.values())


def test_the_one_dmd_bound_is_the_schedule_bound_where_the_lsb_binds():
    for dmd in (XGA, DMDS["dlp9500"]):
        b = bounds.one(bounds.Paces.of(dmd, DCLK), 8)
        assert b.binds == "lsb"
        assert b.rate_hz == pytest.approx(schedule.bound(dmd, DCLK, 8), rel=1e-9)


def test_sequences_held_are_the_store_slots_at_eight_bits():
    from spec.facts import frames_held
    for dmd in (XGA, DMDS["dlp9500"]):
        assert bounds.sequence_frames(dmd, 8) == frames_held(dmd.rows, dmd.columns)
        assert bounds.sequence_frames(dmd, 16, "svec_ddr3") == bounds.sequence_frames(dmd, 8)


def _binds_in_docs():
    """``{(dmd, scheme, depth): binds}`` from the tables of docs/bounds.md's "Beyond one DMD"."""
    text = (ROOT / "docs" / "bounds.md").read_text()
    section = text.split("## Beyond one DMD", 1)[1].split("\n## ", 1)[0]
    out, dmd = {}, None
    for line in section.splitlines():
        heading = re.match(r"\*\*(DLP\d+)", line)
        if heading:
            dmd = heading.group(1).lower()
        row = re.match(r"\| (one|gated|dual|dual_gated), (\d+) bits? \|(?:[^|]*\|){2} ([^|]+) \|", line)
        if row:
            out[(dmd, row.group(1), int(row.group(2)))] = row.group(3).strip()
    return out


def test_the_docs_say_what_binds_each_bound():
    table = _binds_in_docs()
    from sim.bench.bounds_figures import DEPTHS, row_periods
    assert len(table) == 2 * len(bounds.SCHEMES) * len(DEPTHS)
    periods = row_periods()
    for (name, scheme, depth), said in table.items():
        words = [bounds.SCHEMES[scheme](bounds.Paces.of(DMDS[name], DCLK, period), depth).binds
                 for period in (None, periods[name])]
        assert said == (words[0] if words[0] == words[1] else " / ".join(words)), (name, scheme, depth)
