"""Plans beyond one timeline: each group in a plane order of its own, from an offset of its own
(:attr:`~spec.registers.PlaneOrder.GROUPS`).

:mod:`spec.ceiling` bounds the plans of one timeline (one plane order for every group, group
``g`` ``g * stagger`` behind group 0) and finds them short of 300 Hz under TI's strict RST_ACTIVE
reading: a uniform stagger's multiples must keep clear of every difference of the shared
timeline's pulse times. Groups in orders of their own have different differences, so they can
follow one another closer. :func:`solve` searches such plans with a constraint solver (OR-Tools
CP-SAT, the ``solver`` extra) under :class:`Terms`:

* the LSB at the settle path (``t_rst + t_settle`` and the group's block clears), each plane ``e``
  lit ``lsb << e``; a plane shorter than the reload (``t_rst + t_settle`` and the group's load)
  ends in a dark pulse and the next plane comes a reload after it; the frame's last plane ends in
  a dark pulse, and the group is loaded again a reload after it;
* every two pulses of the whole DMD at least ``t_rst`` apart (TI's reading: one RST_ACTIVE);
* one bus: each pulse takes a row cycle; each dark pulse's clears (``clear`` cycles) and each
  plane's rows (one load of ``load`` cycles: the group's rows at the row cycle, or at the
  memory's pace) begin once the group's pulse before them is ``t_rst + t_settle`` old and end by
  their own pulse; nothing on the bus overlaps, frames back to back (a frame's first loads run
  in the one before's tail).

:func:`terms` gives the facts table's terms (no margins: the solver's figures beside the bound);
:func:`sequencer_terms` the sequencer's own (its RST_ACTIVE with margin, hide threshold and dark
gap). :func:`find` searches under the sequencer's terms and hands the plan to the schedule model's
sequencer (:func:`spec.schedule.simulate`: its load queue as it is, row by row), which must play it
with no pulse late: the register set it returns is one the gateware plays cycle for cycle as the
model does. The search is parallel with a time limit: what it finds may differ from run to run; its
lower bound is proved. ``sim.bench.group_orders_figures`` checks the solver's plans with code that
shares nothing with it.
"""

import math
from dataclasses import dataclass, replace

from . import ceiling, schedule
from .plan_search import order_kwargs
from .registers import PlaneOrder
from .schedule import FABRIC_HZ, beats_at, even, groups, row_cycles

__all__ = ["Terms", "GroupPlan", "terms", "sequencer_terms", "solve", "find", "played"]


@dataclass(frozen=True)
class Terms:
    """What a plan must keep to, in ``dmd`` cycles: ``G`` groups, ``depth`` planes each."""
    G: int
    depth: int
    lsb: int
    reload: int
    t_rst: int
    t_settle: int
    row: int
    load: int
    clear: int
    slack: int = 0      # cycles a load must end before its pulse (row cycles others' pulses take)
    # triggered, cycles from a trigger to group 0's first pulse (:func:`spec.schedule.trigger_lead`:
    # the bus ends the operation under way when the trigger comes, other groups' first loads
    # running then, so that no pulse waits for it)
    guard: int = 0


@dataclass
class GroupPlan:
    """A plan: each group's offset and plane order (weight exponents in display order), the
    frame (frames back to back), the start of each group's loads (one per plane, in display
    order) and of its clears (one per dark pulse but the frame's last), and the solver's proven
    lower bound on the frame; ``chained``: each group's next frame follows its own (else every
    group's first pulse is its offset after a trigger that comes once every group has ended its
    frame and group 0 is loaded)."""
    terms: Terms
    frame: int
    offsets: list
    orders: list
    loads: list
    clears: list
    lower: int
    chained: bool = False

    @property
    def rate_hz(self):
        return FABRIC_HZ / self.frame

    @property
    def trigger_offsets(self):
        """Each group's first pulse after the trigger (the registers' ``group_offsets``): the
        offsets and, triggered, the terms' ``guard``."""
        return [o + (0 if self.chained else self.terms.guard) for o in self.offsets]


def terms(dmd, dclk_hz, reset_mode, *, depth=8, row_period=None):
    """The :class:`Terms` of ``dmd`` at ``dclk_hz`` in a phased ``reset_mode``; ``row_period``:
    the rows' pace in a load (default the row cycle, as the rates bench's store stand-in)."""
    R = row_cycles(dmd, beats_at(dclk_hz))
    t_rst, t_settle = ceiling.facts_cycles()
    grp = groups(dmd, reset_mode)
    size = max(len(b) for b in grp)
    rows = size * dmd.rows_per_block
    load = (rows - 1) * (row_period or R) + R
    clear = size * dmd.clear_row_cycles * R
    return Terms(len(grp), depth, even(t_rst + t_settle + clear), t_rst + t_settle + load,
                 t_rst, t_settle, R, load, clear)


def sequencer_terms(dmd, dclk_hz, reset_mode, *, margin=0, **plan_kwargs):
    """The :class:`Terms` the sequencer keeps, and the one-timeline plan they come from
    (:func:`spec.schedule.plan`: its RST_ACTIVE with the sequencer's margin, its hide threshold
    and dark gap, its shortest LSB); ``plan_kwargs``: that function's (``words_per_cycle``,
    ``trigger_hold``, ...). ``margin`` (even): cycles more for every load, before its pulse and
    in the dark gap (and hide threshold) that covers a reload, for a memory that may stall."""
    base = schedule.plan(dmd, dclk_hz, reset_mode=reset_mode, **order_kwargs(PlaneOrder.TABLE, 8), **plan_kwargs)
    p = base.params
    assert p.hide == p.dark_gap, "a plane hides a load exactly when it is as long as a dark gap"
    assert margin % 2 == 0, "dark gaps are even"
    base = replace(base, params=replace(p, hide=p.hide + margin, dark_gap=p.dark_gap + margin))
    t = terms(dmd, dclk_hz, reset_mode, row_period=p.row_period)
    # a load done the slack the spread search leaves it for other groups' pulses taking row cycles
    t = replace(t, lsb=even(base.lsb_min), reload=p.hide + margin, t_rst=p.t_rst, t_settle=p.t_settle,
                slack=2 * t.row * t.G + margin, guard=schedule.trigger_lead(dmd, p.beats))
    return t, base


def solve(t, *, limit=None, seconds=60.0, workers=2, seed=0, chained=False):
    """The fastest plan the solver finds within ``seconds`` (below ``limit`` frame cycles), or
    None. Each load may begin anywhere in its window (a scheduler by deadline could serve it so;
    the sequencer's queue serves loads in the order of the pulses that freed them). The search
    is parallel (``workers``): what it finds in a given time may differ from run to run; its
    lower bound is proved. ``chained``: each group's next frame follows its own, a dark gap after
    its last dark pulse (the frame is a group's span, and the groups' offsets, by which frames
    overlap, are whatever the first plan found has)."""
    from ortools.sat.python import cp_model

    problem = _Problem(cp_model.CpModel(), t, limit)
    for g in range(t.G):
        problem.group(g, chained)
    m = problem.m
    if not chained and t.guard:
        problem.trigger()
    m.add_no_overlap(problem.rst)
    m.add_no_overlap(problem.bus)
    # (chained, the frame is each group's span: the shortest, the last plane a dark one)
    m.minimize(problem.F)
    solver = cp_model.CpSolver()
    solver.parameters.max_time_in_seconds = seconds
    solver.parameters.num_workers = workers
    solver.parameters.random_seed = seed
    if solver.solve(m) not in (cp_model.OPTIMAL, cp_model.FEASIBLE):
        return None
    return problem.solution(solver, chained)


class _Problem:
    """The constraint model :func:`solve` hands the solver, built a group at a time: the
    variables, and the intervals that must not overlap (RST_ACTIVE windows and the bus's
    operations), gathered as the groups add them."""

    def __init__(self, m, t, limit):
        self.m, self.t = m, t
        self.frozen = t.t_rst + t.t_settle
        self.lengths = [t.lsb << e for e in range(t.depth)]
        self.dark = [n < t.reload for n in self.lengths]
        self.span = sum(self.lengths) + t.reload * sum(self.dark)     # a group's planes, dark gaps included
        self.H = limit or 4 * (self.span + t.G * t.reload)
        self.F = m.new_int_var(0, self.H, "frame")
        self.rst, self.bus, self.keep = [], [], []
        self.firsts = []

    def var(self, name, lo=None, hi=None):
        H = self.H
        return self.m.new_int_var(-H if lo is None else lo, 3 * H if hi is None else hi, name)

    def on_bus(self, start, size, name, present=None):
        m, F = self.m, self.F
        # the interval and its copy a frame later: a periodic schedule
        for k in (0, 1):
            s = self.var(f"{name}@{k}")
            m.add(s == start + k * F)
            e = self.var(f"{name}@{k}e")
            self.bus.append(m.new_interval_var(s, size, e, name) if present is None else
                            m.new_optional_interval_var(s, size, e, present, name))

    def pulse(self, at, name, present=None):
        m, F, t = self.m, self.F, self.t
        for k in (0, 1):
            s = self.var(f"{name}@{k}")
            m.add(s == at + k * F)
            self.rst.append(m.new_fixed_size_interval_var(s, t.t_rst, name) if present is None else
                            m.new_optional_fixed_size_interval_var(s, t.t_rst, present, name))
        self.on_bus(at, t.row, name + "/bus", present)

    def group(self, g, chained):
        """Group ``g``'s frame: its offset, its planes in an order the solver picks (a circuit
        through them), their pulses, loads and clears, and the next frame's start."""
        m, t, F, H, var = self.m, self.t, self.F, self.H, self.var
        frozen, lengths, dark, span, firsts = self.frozen, self.lengths, self.dark, self.span, self.firsts
        N = t.depth                                             # the circuit's frame-boundary node
        o = 2 * var(f"o{g}/2", 0, H // 2) if g else m.new_constant(0)     # even: decisions on even cycles
        # groups but the first are alike: their offsets in rising order, first pulses a
        # RST_ACTIVE apart as any two pulses (a symmetry the search need not explore)
        if g > 1:
            m.add(firsts[-1] + t.t_rst <= o)
        firsts.append(o)
        s = [var(f"s{g}.{e}", 0, H) for e in range(N)]
        occupied = [n + (t.reload if d else 0) for n, d in zip(lengths, dark, strict=True)]
        end = o + span
        x = {(a, b): m.new_bool_var(f"x{g}.{a}.{b}") for a in range(N + 1) for b in range(N + 1) if a != b}
        m.add_circuit([(a, b, lit) for (a, b), lit in x.items()])
        last_dark = m.new_bool_var(f"lastdark{g}")
        m.add(sum(x[e, N] for e in range(N) if dark[e]) == last_dark)
        final = var(f"final{g}", 0, 2 * H)               # the frame's last dark pulse
        m.add(final == end - t.reload).only_enforce_if(last_dark)
        m.add(final == end).only_enforce_if(~last_dark)
        # the next frame: triggered, every group's first pulse its offset after the trigger,
        # which comes once every group has ended its frame (its last dark pulse) and group 0 is
        # loaded again (the others' first loads, below, by their own offsets: frames never
        # overlap); chained, each group's own frame after its own (a frame of every group's span)
        if chained:
            m.add(F == final + t.reload - o)
        else:
            m.add(F >= final + t.guard)
        loads, clears = [], []
        for e in range(N):
            m.add(s[e] == o).only_enforce_if(x[N, e])
            m.add(s[e] + occupied[e] == end).only_enforce_if(x[e, N])
            for a in range(N):
                if a != e:
                    m.add(s[e] == s[a] + occupied[a]).only_enforce_if(x[a, e])
            self.pulse(s[e], f"p{g}.{e}")
            # the load: after the group's pulse before it (plane a's, or its dark pulse; the
            # first plane's: the frame before's last dark pulse) and t_rst + t_settle, done by
            # its own pulse
            before = var(f"b{g}.{e}")
            for a in range(N):
                if a != e:
                    m.add(before == s[a] + (lengths[a] if dark[a] else 0)).only_enforce_if(x[a, e])
            m.add(before == final - F).only_enforce_if(x[N, e])
            ld = var(f"l{g}.{e}", -H, H)
            m.add(ld >= before + frozen)
            done = m.add(ld + t.load + t.slack <= s[e])
            if g == 0 and not chained:
                # group 0's first plane loaded by the trigger, its guard before the pulse
                m.add(ld + t.load + t.guard <= s[e]).only_enforce_if(x[N, e])
            if chained:
                # the first plane's load, in the dark gap after the group's own frame before:
                # the slack that gap leaves (the sequencer's dark gap covers one load and its
                # own slack), not the one a load behind a plane keeps
                done.only_enforce_if(~x[N, e])
                m.add(ld + t.reload - frozen <= s[e]).only_enforce_if(x[N, e])
            self.on_bus(ld, t.load, f"l{g}.{e}")
            loads.append(ld)
            if dark[e]:
                # its dark pulse, and the clears before it (the frame's last: at the end)
                self.pulse(s[e] + lengths[e], f"d{g}.{e}")
                c = var(f"c{g}.{e}", 0, H)
                m.add(c >= s[e] + frozen)
                m.add(c + t.clear <= s[e] + lengths[e])
                self.on_bus(c, t.clear, f"c{g}.{e}")
                clears.append((e, c))
        # the frame's last dark pulse when the last plane hides loads: it needs clears too
        self.pulse(end, f"f{g}", ~last_dark)
        c = var(f"cf{g}", 0, 2 * H)
        m.add(c + t.clear <= end)
        for a in range(N):
            m.add(c >= s[a] + frozen).only_enforce_if(x[a, N])
        self.on_bus(c, t.clear, f"cf{g}", ~last_dark)
        self.keep.append((o, s, loads, clears, c))

    def trigger(self):
        """Triggered, the trigger's guard before group 0's pulse: RST_ACTIVE over for that pulse
        by then."""
        m, t, F = self.m, self.t, self.F
        for k in (0, 1):
            at = self.var(f"trigger@{k}")
            m.add(at == k * F - t.guard)
            self.rst.append(m.new_fixed_size_interval_var(at, t.guard, f"trigger@{k}"))

    def solution(self, solver, chained):
        """The :class:`GroupPlan` the solver's values give: each group's order by its pulses'
        times, its loads in that order, its clears in dark-pulse order."""
        v, N = solver.value, self.t.depth
        offsets, orders, all_loads, all_clears = [], [], [], []
        for o, s, loads, clears, c in self.keep:
            order = sorted(range(N), key=lambda e: v(s[e]))
            offsets.append(v(o))
            orders.append(tuple(order))
            all_loads.append([v(loads[e]) for e in order])
            cl = {e: v(ce) for e, ce in clears}
            # clears in dark-pulse order, the frame's last dark pulse's last
            all_clears.append([cl[e] for e in order[:-1] if e in cl] + [cl.get(order[-1], v(c))])
        return GroupPlan(self.t, v(self.F), offsets, orders, all_loads, all_clears,
                         math.ceil(solver.best_objective_bound), chained)


def find(dmd, dclk_hz, reset_mode, *, seconds=60.0, workers=2, extra_rows=4, margin=0, chained=False,
         attempts=4, **plan_kwargs):
    """The fastest plan of groups in orders of their own the solver finds within ``seconds``
    under the sequencer's terms (:func:`sequencer_terms`; ``plan_kwargs`` as
    :func:`spec.schedule.plan`'s), that the schedule model's sequencer plays with no pulse late:
    (:class:`spec.schedule.Plan` of :attr:`~spec.registers.PlaneOrder.GROUPS`, its
    :class:`GroupPlan`), or None. The solver places each load anywhere in its window, the model's
    queue where it comes: should the model make a pulse late, the LSB takes a row cycle more, up
    to ``extra_rows``. Triggered, three searches at each LSB: each load done the sequencer terms'
    slack before its pulse (room for other groups' pulses), and two (seeds) with none but
    ``margin`` (tighter, so the model's queue may make it late); the fastest plan that plays is
    kept, every offset the terms' ``guard`` more (:attr:`GroupPlan.trigger_offsets`).
    ``margin``: as :func:`sequencer_terms`'s. ``chained``: each
    frame follows the one before without a trigger (:attr:`~spec.schedule.Params.chain`), each
    group its own frame after its own; the solver's loads may be placed where the sequencer's
    queue would not put them, so up to ``attempts`` searches (seeds) at each LSB."""
    seq_terms, base = sequencer_terms(dmd, dclk_hz, reset_mode, margin=margin, **plan_kwargs)
    if chained:
        base = replace(base, params=replace(base.params, chain=True))
    # triggered, the loads' slack for other groups' pulses both ways: none (the memory's margin
    # only) and the spread search's; chained, the frame is a group's span whatever the slack
    slacks = ((seq_terms.slack, attempts),) if chained else ((margin, 2), (seq_terms.slack, 1))
    for extra in range(extra_rows + 1):
        kept = []
        for slack, seeds in slacks:
            t = replace(seq_terms, lsb=seq_terms.lsb + extra * seq_terms.row, slack=slack)
            for seed in range(seeds):
                found = solve(t, seconds=seconds, workers=workers, seed=seed, chained=chained)
                if found is None:
                    break
                plan = played(dmd, base, t.lsb, found.orders, found.trigger_offsets)
                if plan is not None:
                    kept.append((plan, found))
                    if chained:            # (every chained plan has the same frame)
                        break
        if kept:
            return min(kept, key=lambda pair: pair[0].frame_cycles)
    return None


#: Frames a chained plan is played for by :func:`played` (the first ones start from a trigger).
CHAINED_FRAMES = 6
#: Frames a triggered plan is played for by :func:`played`, back to back.
TRIGGERED_FRAMES = 4


def played(dmd, base, lsb, orders, offsets):
    """``base`` (a :func:`sequencer_terms` plan) with each group's order and offset, at ``lsb``, as
    the schedule model's sequencer plays it from a trigger (chained: :data:`CHAINED_FRAMES`
    frames, each after the one before; else :data:`TRIGGERED_FRAMES` triggered back to back):
    the :class:`spec.schedule.Plan` (its trigger-to-trigger period, or chained its frame period),
    or None if a pulse comes late."""
    p = replace(base.params, lsb=lsb, order=PlaneOrder.GROUPS, group_tables=tuple(map(tuple, orders)),
                group_offsets=tuple(offsets))
    frame = schedule.Frame(0, len(orders[0]))
    if p.chain:
        n, first = CHAINED_FRAMES, schedule.ready_cycle(dmd, p, frame)
        late = schedule.simulate(dmd, p, [frame] * n, [first], max_frames=n - 1).late
    else:
        # (the frames after the first start from triggers that wait for group 0's load only)
        late = schedule.back_to_back(dmd, p, frame, TRIGGERED_FRAMES).late
    if late:
        return None
    kind = "the solver's, chained" if p.chain else "the solver's"
    return replace(base, params=p, frame_cycles=schedule.frame_period(dmd, p, frame),
                   binds=f"groups in plane orders of their own ({kind}), LSB {lsb}")
