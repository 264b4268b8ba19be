"""Plans of groups in plane orders of their own (:mod:`spec.group_orders`): the solver's plans pass
the independent check (:mod:`sim.bench.group_orders_figures`), reach the one-timeline ceiling where
that is optimal, never pass the bound, and the check fails each rule it checks when that rule is
broken; the plan finder's register set is one the projector takes, played by the model with no pulse
late."""

import copy
from dataclasses import replace

import pytest

from sim.bench import group_orders_figures as go
from spec import ceiling, records, schedule
from spec import group_orders as solver
from spec.facts import DMDS, TEST_DMD
from spec.registers import TIMED_NOTICE, PlaneOrder, ResetMode

DEPTH = 4


@pytest.fixture(scope="module")
def plans():
    out = {}
    for mode in (ResetMode.DUAL, ResetMode.SINGLE):
        top = ceiling.ceiling_of_mode(TEST_DMD, 200e6, mode, depth=DEPTH)
        # (no frame longer than the ceiling's, whose plan is one of the solver's: the search
        # starts from a small space, so its proof comes within the time)
        out[mode] = (solver.solve(solver.terms(TEST_DMD, 200e6, mode, depth=DEPTH), seconds=5,
                                  limit=top.frame_cycles), top)
    return out


@pytest.mark.parametrize("mode", [ResetMode.DUAL, ResetMode.SINGLE])
def test_plans_are_legal_and_bounded(plans, mode):
    plan, top = plans[mode]
    assert go.check(plan) == []
    # nothing beats the bound, nor the solver's proved lower bound; the loads are short on the
    # test DMD, so the ceiling's plan (one order, a uniform stagger) is one of the solver's: its
    # proved bound is no later. With two groups the solver proves its plan optimal, and it beats
    # the ceiling by the stagger: the ceiling's trigger waits for every group to be loaded again,
    # the solver's only for group 0 (the other's last dark pulse made, its load due by its offset)
    assert schedule.FABRIC_HZ / schedule.bound(TEST_DMD, 200e6, DEPTH) <= plan.lower <= plan.frame
    assert plan.lower <= top.frame_cycles
    if mode == ResetMode.DUAL:
        assert plan.frame == plan.lower == top.frame_cycles - top.stagger


def _broken(plan, how):
    p = copy.deepcopy(plan)
    t = p.terms
    if how == "spacing":
        p.offsets[1] = p.offsets[0]                             # every pulse of two groups at once
    elif how == "load late":
        p.loads[0][1] += p.terms.lsb << DEPTH
    elif how == "load early":
        p.loads[0][1] -= p.terms.lsb << DEPTH
    elif how == "clear":
        p.clears[0][0] += t.clear + 2 * t.row
    elif how == "bus":
        p.loads[1] = [p.loads[0][0]] + p.loads[1][1:]           # two loads at once on the bus
    elif how == "order":
        p.orders[0] = (p.orders[0][0],) * DEPTH
    elif how == "frame":
        p.frame -= t.reload
    return p


@pytest.mark.parametrize("how", ["spacing", "load late", "load early", "clear", "bus", "order", "frame"])
def test_check_fails_each_broken_rule(plans, how):
    plan, _ = plans[ResetMode.SINGLE]
    assert go.check(plan) == []
    assert go.check(_broken(plan, how)) != []



def test_the_models_sequencer_plays_each_group_in_its_own_order():
    # one timeline written as group orders and offsets: the model plays exactly the same
    t, base = solver.sequencer_terms(TEST_DMD, 200e6, ResetMode.SINGLE, trigger_hold=True)
    p, frame = base.params, schedule.Frame(0, 8)
    exps = tuple(schedule.exponents(p.order, p.order_table, 8, p.anchor))
    same = replace(p, order=PlaneOrder.GROUPS, group_tables=(exps,) * t.G,
                   group_offsets=tuple(g * p.stagger for g in range(t.G)))
    first = schedule.ready_cycle(TEST_DMD, p, frame)
    assert (schedule.simulate(TEST_DMD, same, [frame], [first]).commands
            == schedule.simulate(TEST_DMD, p, [frame], [first]).commands)
    # each group in an order of its own (the table turned round by the group), from an offset
    # of its own: the model shows each group's planes in its order, from its offset
    tables = tuple(exps[g:] + exps[:g] for g in range(t.G))
    offsets = tuple(g * p.stagger + (g % 2) * 2 * t.t_rst for g in range(t.G))
    q = replace(p, order=PlaneOrder.GROUPS, group_tables=tables, group_offsets=offsets)
    r = schedule.simulate(TEST_DMD, q, [frame], [schedule.ready_cycle(TEST_DMD, q, frame)])
    for g in range(t.G):
        shown = [e for _, h, kind, _, e in r.pulses if h == g and kind == "plane"]
        assert tuple(shown) == tables[g]
    # (the first planes are loaded before the trigger and the offsets t_rst apart: the first
    # pulses come on time, whatever comes late after them)
    starts = [min(at for at, h, *_ in r.pulses if h == g) for g in range(t.G)]
    assert [s - starts[0] for s in starts] == list(offsets)
    # the order and the tables go together
    with pytest.raises(ValueError):
        replace(q, order=PlaneOrder.TABLE)
    with pytest.raises(ValueError):
        replace(p, order=PlaneOrder.GROUPS)


def test_the_finder_gives_a_register_set_the_projector_takes():
    found = solver.find(TEST_DMD, 200e6, ResetMode.SINGLE, seconds=3, trigger_hold=True)
    assert found is not None
    plan, groups = found
    p = plan.params
    assert p.order == PlaneOrder.GROUPS and go.check(groups) == []
    # (triggered, every offset the terms' guard more than the solver's: group 0's first pulse
    # leaves the bus time to end a row or a clear under way when the trigger comes)
    assert groups.terms.guard == schedule.trigger_lead(TEST_DMD) == 4
    assert (p.group_tables, p.group_offsets) == (tuple(groups.orders),
                                                 tuple(o + groups.terms.guard for o in groups.offsets))
    frame = schedule.Frame(0, 8)
    assert schedule.simulate(TEST_DMD, p, [frame], [schedule.ready_cycle(TEST_DMD, p, frame)]).late == 0
    assert plan.frame_cycles == schedule.frame_period(TEST_DMD, p, frame)
    wire = records.register_wire(p.registers(TEST_DMD))
    faults = records.register_faults(wire, TEST_DMD)
    assert [k for k, bad in faults.items() if bad] == []


def test_a_margin_ends_every_load_that_much_sooner():
    """``margin``: every load ends that much sooner before its pulse, and the dark gap (and the
    hide threshold with it) covers it; the finder's plan keeps it (the independent check with the
    margin in its terms: the sequencer terms' slack, or the margin alone)."""
    bare, start = solver.sequencer_terms(TEST_DMD, 200e6, ResetMode.SINGLE, trigger_hold=True)
    kept, base = solver.sequencer_terms(TEST_DMD, 200e6, ResetMode.SINGLE, margin=8, trigger_hold=True)
    assert (kept.slack, kept.reload) == (bare.slack + 8, bare.reload + 8)
    assert base.params.dark_gap == base.params.hide == start.params.dark_gap + 8
    plan, groups = solver.find(TEST_DMD, 200e6, ResetMode.SINGLE, seconds=3, margin=8, trigger_hold=True)
    assert groups.terms.slack in (kept.slack, 8) and go.check(groups) == []
    assert plan.params.dark_gap == base.params.dark_gap
    with pytest.raises(AssertionError):
        solver.sequencer_terms(TEST_DMD, 200e6, ResetMode.SINGLE, margin=3)


def test_chained_plans_end_each_groups_frame_at_its_own():
    """Chained, each group's next frame follows its own: the solver's plan passes the independent
    check with that rule, and its frame is a group's planes and reloads (no group waits for the
    last one to be loaded again), shorter than the triggered plan's; the finder's chained
    register set plays in the model with no pulse late, each group's next first pulse a dark gap
    after its last dark pulse."""
    t = solver.terms(TEST_DMD, 200e6, ResetMode.DUAL, depth=DEPTH)
    triggered = solver.solve(t, seconds=5)
    chained = solver.solve(t, seconds=5, chained=True)
    assert chained.chained and go.check(chained) == []
    lengths = [t.lsb << e for e in range(DEPTH)]
    span = sum(lengths) + t.reload * sum(n < t.reload for n in lengths)
    assert span <= chained.lower <= chained.frame <= triggered.frame
    # a chained frame any shorter leaves some group no reload
    assert go.check(replace(chained, frame=chained.frame - 2)) != []
    plan, groups = solver.find(TEST_DMD, 200e6, ResetMode.SINGLE, seconds=3, chained=True, trigger_hold=True)
    p = plan.params
    assert p.chain and go.check(groups) == []
    frame = schedule.Frame(0, 8)
    r = schedule.simulate(TEST_DMD, p, [frame] * 4, [schedule.ready_cycle(TEST_DMD, p, frame)], max_frames=3)
    assert r.late == 0
    for g in range(len(p.group_tables)):
        firsts = [at for at, h, kind, _, e in r.pulses if h == g and kind == "plane" and e == p.group_tables[g][0]]
        darks = [at for at, h, kind, fi, _ in r.pulses if h == g and kind == "dark" and fi == 1]
        assert firsts[2] == darks[-1] + p.dark_gap


def test_a_trigger_at_any_cycle_after_ready_makes_no_pulse_late(monkeypatch):
    """Once frames follow triggers, a trigger waits for group 0's load only, and other groups'
    first loads run on: a trigger may come mid-row. Group 0's offset (the terms' guard, a row
    cycle and the bus's notice on the DLP7000) lets the bus end the row before the first pulse, so a trigger at any
    cycle of two row cycles from the first it may come at makes no pulse late, in the schedule
    model on the full DLP7000 at 200 MHz (a plan the finder found there). With group 0 at once
    under the same rule most of those triggers make its pulse late (so the sequencer waits for
    every group then)."""
    dmd = DMDS["dlp7000"]
    t, base = solver.sequencer_terms(dmd, 200e6, ResetMode.DUAL, trigger_hold=True)
    orders = ((6, 5, 1, 3, 2, 7, 0, 4), (7, 3, 0, 5, 1, 2, 6, 4), (5, 6, 1, 2, 4, 0, 3, 7), (6, 7, 1, 4, 5, 2, 3, 0),
              (4, 7, 0, 5, 2, 1, 3, 6), (3, 1, 4, 7, 6, 2, 0, 5), (4, 5, 1, 0, 7, 2, 3, 6), (5, 6, 4, 7, 2, 1, 3, 0))
    offsets = (0, 2222, 3136, 5028, 5942, 8472, 10088, 11034)
    frame = schedule.Frame(0, 8)
    assert t.guard == schedule.trigger_lead(dmd) == t.row + TIMED_NOTICE == 18

    def lates(guard):
        p = replace(base.params, lsb=t.lsb, order=PlaneOrder.GROUPS, group_tables=orders,
                    group_offsets=tuple(o + guard for o in offsets), trigger_hold=False)
        first = schedule.ready_cycle(dmd, p, frame)
        ready = schedule.back_to_back(dmd, p, frame, 2).accepted[1]
        out = []
        for k in range(2 * t.row):
            r = schedule.simulate(dmd, p, [frame], [first, ready + k], max_frames=1)
            assert len(r.accepted) == 2
            out.append(r.late)
        return out

    assert lates(t.guard) == [0] * 2 * t.row
    monkeypatch.setattr(schedule._Model, "steady", lambda self: not self.reloaded)
    assert sum(n > 0 for n in lates(0)) > t.row
