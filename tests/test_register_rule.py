"""The rule for what the projector can play (:func:`spec.records.register_faults`), against the
schedule model and on the gateware.

In global mode the rule is sound: every set it takes plays with no pulse late. Hypothesis draws
global sets near each bound the rule names (the least significant plane against the clears, the
hide threshold and the dark gap against the reload) and the schedule model plays each one it
takes. On the gateware, drawn sets go as sequencer records through the endpoint (the parser
hands on exactly those the rule takes), and each one taken is played on the sequencer's
generated Verilog: the rule-checking DLPC410 model on its pins, ``pulses_late`` 0, every grey
level of the ramp exact under the camera model. The plan finder's plans pass the rule in every
reset mode. (In a phased mode the rule is what each group needs alone; the groups' loads share
the bus, so a set it takes may still be late: ``sim.bench.registers_figures`` counts how often.)
"""

import dataclasses

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gateware.dlpc410.trigger import PIN_TO_STROBE
from host import codec
from sim.models import frames
from sim.models.endpoint_traffic import A
from sim.rigs.seq_rig import run_rig
from sim.tb import endpoint_sim
from sim.tb.plane_source import ramp_image
from sim.tb.seq_sim import frame_lights
from spec import records, schedule
from spec.facts import DMDS, TEST_DMD
from spec.registers import PlaneOrder, ResetMode

#: DMDs and DCLK (beats) the model checks are drawn on.
GEOMETRIES = [("test", 200e6), ("test_400", 400e6), ("test4", 200e6), ("test4_400", 400e6)]
ORDERS = [PlaneOrder.MSB_FIRST, PlaneOrder.LSB_FIRST]


def faults(dmd, p):
    failed = records.register_faults(records.register_wire(p.registers(dmd)), dmd, p.beats)
    return [name for name, bad in failed.items() if bad]


def bounds(dmd, p):
    """(settle and clears, reload) of ``p``'s groups, from the rule's own terms."""
    wire = records.register_wire(p.registers(dmd))
    clears, reload = records.group_reload(wire, dmd, p.beats)
    return p.t_rst + p.t_settle + clears, reload


@st.composite
def global_sets(draw, geometries=GEOMETRIES, chained=(False, True)):
    """A global-mode set near the rule's bounds: a plan's (chained or triggered, as ``chained``
    allows), then its LSB, hide threshold and dark gap each moved to near a bound, to near the
    plan's own value, or anywhere."""
    name, dclk = draw(st.sampled_from(geometries))
    dmd = DMDS[name]
    base = schedule.plan(dmd, dclk, reset_mode=ResetMode.GLOBAL, order=draw(st.sampled_from(ORDERS)),
                         t_rst_s=draw(st.sampled_from([40, 80, 200])) / dclk,
                         t_settle_s=draw(st.sampled_from([6, 60, 120])) / dclk,
                         chain=draw(st.sampled_from(chained))).params
    floor, reload = bounds(dmd, base)
    near = st.integers(-6, 12).map(lambda k: 2 * k)
    lsb = max(2, draw(st.sampled_from([floor, base.lsb])) + draw(near))
    hide = draw(st.one_of(st.sampled_from([base.hide, 0, 1 << 30]), st.sampled_from([reload, lsb, 2 * lsb, 4 * lsb])
                          .flatmap(lambda b: near.map(lambda k: max(0, b + k)))))
    dark_gap = max(2, draw(st.sampled_from([reload + reload % 2, base.dark_gap])) + draw(near))
    return dmd, dataclasses.replace(base, lsb=lsb, hide=hide, dark_gap=dark_gap)


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(global_sets())
def test_global_sets_the_rule_takes_play_on_time(case):
    dmd, p = case
    if not faults(dmd, p):
        assert schedule.on_time(dmd, p, schedule.Frame(0, 8)), p


@pytest.mark.parametrize("mode", list(ResetMode))
@pytest.mark.parametrize("name,dclk", GEOMETRIES)
def test_the_plan_finders_plans_pass(name, dclk, mode):
    dmd = DMDS[name]
    for order in ORDERS:
        p = schedule.plan(dmd, dclk, reset_mode=mode, order=order, t_rst_s=80 / dclk, t_settle_s=60 / dclk).params
        assert faults(dmd, p) == [], (mode, order)


def test_each_bound_refuses_alone():
    """One cycle pair under each bound is refused by that check alone; at the bound it is taken."""
    p = schedule.plan(TEST_DMD, 200e6, reset_mode=ResetMode.GLOBAL, t_rst_s=80 / 200e6, t_settle_s=60 / 200e6).params
    floor, reload = bounds(TEST_DMD, p)
    at = dataclasses.replace(p, lsb=floor + floor % 2, hide=reload, dark_gap=reload + reload % 2)
    assert faults(TEST_DMD, at) == []
    assert faults(TEST_DMD, dataclasses.replace(at, lsb=at.lsb - 2)) == ["lsb_keepable"]
    assert faults(TEST_DMD, dataclasses.replace(at, hide=reload - 1)) == ["hide_keepable"]
    assert faults(TEST_DMD, dataclasses.replace(at, dark_gap=at.dark_gap - 2)) == ["dark_gap_keepable"]
    # a hide below the reload is kept when no plane is that long, or the LSB holds the reload
    assert faults(TEST_DMD, dataclasses.replace(at, hide=(at.lsb << 7) + 1)) == []
    long_lsb = reload + reload % 2
    assert faults(TEST_DMD, dataclasses.replace(at, lsb=long_lsb, hide=0)) == []
    # chained with every plane hiding, no dark pulse comes: the gap is not looked at
    assert faults(TEST_DMD, dataclasses.replace(at, lsb=long_lsb, hide=0, chain=True, dark_gap=2)) == []


@pytest.mark.parametrize("name,dclk", GEOMETRIES)
def test_the_gated_plans_pass(name, dclk):
    dmd = DMDS[name]
    p = schedule.plan_gated(dmd, dclk, t_rst_s=80 / dclk, t_settle_s=60 / dclk).params
    assert faults(dmd, p) == []


def test_each_gated_bound_refuses_alone():
    """Gated planes: one step past each bound is refused by that check alone; at it, taken."""
    at = schedule.plan_gated(TEST_DMD, 200e6, t_rst_s=80 / 200e6, t_settle_s=60 / 200e6).params
    floor, reload = bounds(TEST_DMD, at)
    at = dataclasses.replace(at, light_lead=schedule.MIRRORS_SETTLED)
    end = at.gated_time - at.light_lead - schedule.LIGHT_FALL
    at = dataclasses.replace(at, light_times=(1,) * 7 + (end,))
    assert faults(TEST_DMD, at) == []
    assert faults(TEST_DMD, dataclasses.replace(at, light_times=(1,) * 7 + (end + 1,))) == ["light_times_keepable"]
    assert faults(TEST_DMD, dataclasses.replace(at, light_lead=at.light_lead - 1)) == ["light_lead_keepable"]
    assert faults(TEST_DMD, dataclasses.replace(at, gated_time=at.gated_time + 1)) == ["gated_time_even"]
    assert faults(TEST_DMD, dataclasses.replace(at, gated_planes=0x7F)) == ["gated_planes_whole"]
    phased = dataclasses.replace(at, reset_mode=ResetMode.DUAL, stagger=0)
    assert "gated_global" in faults(TEST_DMD, phased)
    assert "gated_global" not in faults(TEST_DMD, dataclasses.replace(phased, gated_planes=0))
    # a gated plane shorter than the reload that hides, or than a dark pulse's settle and clears:
    # refused as such an LSB would be (its light, behind the mirrors' settle, cannot fit either)
    short = dataclasses.replace(at, gated_time=reload - reload % 2 - 2, light_times=(0,) * 8, hide=floor)
    assert short.gated_time >= floor and "gated_time_keepable" in faults(TEST_DMD, short)
    assert "gated_time_keepable" not in faults(TEST_DMD, dataclasses.replace(short, hide=reload))
    assert "gated_time_keepable" in faults(TEST_DMD, dataclasses.replace(short, gated_time=floor - floor % 2 - 2,
                                                                          hide=reload))


@st.composite
def gated_sets(draw):
    """A gated plan's set with its gated time, lead and largest light moved near their bounds."""
    name, dclk = draw(st.sampled_from(GEOMETRIES))
    dmd = DMDS[name]
    base = schedule.plan_gated(dmd, dclk, t_rst_s=draw(st.sampled_from([40, 200])) / dclk,
                               t_settle_s=draw(st.sampled_from([6, 120])) / dclk,
                               chain=draw(st.booleans())).params
    floor, reload = bounds(dmd, base)
    near = st.integers(-6, 6).map(lambda k: 2 * k)
    gated_time = max(2, draw(st.sampled_from([floor, reload, base.gated_time])) + draw(near))
    hide = draw(st.sampled_from([base.hide, 0, 1 << 30]))
    lead = schedule.MIRRORS_SETTLED + draw(st.integers(-2, 4))
    light = max(0, gated_time - lead - schedule.LIGHT_FALL + draw(st.integers(-3, 2)))
    return dmd, dataclasses.replace(base, gated_time=gated_time, hide=hide, light_lead=lead,
                                    light_times=base.light_times[:7] + (light,))


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(gated_sets())
def test_gated_sets_the_rule_takes_play_on_time(case):
    dmd, p = case
    if not faults(dmd, p):
        assert schedule.on_time(dmd, p, schedule.Frame(0, 8)), p


#: The gateware check: sets drawn on the test DMD at one beat (the endpoint's and the rig's
#: build), triggered (a frame a trigger, so that each run ends).
ON_GATEWARE = [("test", 200e6)]


@st.composite
def edge_sets(draw):
    """A global-mode set the rule takes with little to spare (each of the LSB, hide threshold
    and dark gap within a few cycles above its bound, or the hide threshold beyond every plane),
    and beside it the same set with one of them a step below its bound."""
    dmd, p = draw(global_sets(ON_GATEWARE, chained=(False,)))
    floor, reload = bounds(dmd, p)
    slack = st.integers(0, 6).map(lambda k: 2 * k)
    lsb = floor + floor % 2 + draw(slack)
    p = dataclasses.replace(p, lsb=lsb, dark_gap=reload + reload % 2 + draw(slack),
                            hide=draw(st.one_of(slack.map(lambda k: reload + k), st.just((lsb << 7) + 1))))
    below = draw(st.sampled_from([{"lsb": floor - floor % 2 - 2}, {"dark_gap": reload - reload % 2 - 2},
                                  {"hide": reload - 1}]))
    if "hide" in below and p.hide > reload + 12:
        below = {"lsb": floor - floor % 2 - 2}
    return p, dataclasses.replace(p, **below)


@pytest.mark.verilog
@settings(max_examples=4, deadline=None, derandomize=True, database=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(cases=st.lists(edge_sets(), min_size=2, max_size=2))
def test_drawn_sets_on_the_gateware(cases, test_name):
    """Sets at the rule's edge through the endpoint: those handed on are those the rule takes
    (each taken one, not the one a step below it); each taken plays on the sequencer's Verilog
    with no pulse late and every grey level exact."""
    sets = [p for pair in cases for p in pair]
    wires = [records.register_wire(p.registers(TEST_DMD)) for p in sets]
    sequence = [(frames.udp(A, codec.sequencer_record(wire, k)), False) for k, wire in enumerate(wires)]
    out = endpoint_sim.run(sequence, name="register_rule", settle_each=200, gap=(0, 20), waves=False)
    taken = [p for p in sets if not faults(TEST_DMD, p)]
    assert taken == [taken_one for taken_one, _ in cases]
    assert out["registers"] == [records.registers_bits(w) for p, w in zip(sets, wires, strict=True) if p in taken]
    for k, p in enumerate(taken):
        model_frame = [schedule.Frame(0, 8)]
        pin = max(g.loaded_at for g in schedule.simulate(TEST_DMD, p, model_frame).groups) + 6
        model_run = schedule.simulate(TEST_DMD, p, model_frame, [pin + PIN_TO_STROBE])
        assert model_run.late == 0
        end = model_run.commands[-1][0] + 64
        run = run_rig(TEST_DMD, p, [(0, 8)], pins=[pin], cycles=end, name=f"{test_name}_{k}")
        assert run.status["late"] == 0 and run.status["frames"] == 1, run.status
        (light,) = frame_lights(run.model, run.frames())
        expect = ramp_image(TEST_DMD, 0).astype(np.int64) * p.lsb
        assert np.array_equal(light, expect), f"max error {np.abs(light - expect).max() / p.lsb} LSB"
