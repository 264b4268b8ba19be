"""Plans beyond one timeline: each group in a plane order of its own, from an offset of its own.

:mod:`spec.ceiling` bounds the plans the sequencer plays (one plane order for every group, group
``g`` ``g * stagger`` behind group 0) and finds them short of 300 Hz under TI's strict RST_ACTIVE
reading: a uniform stagger's multiples must keep clear of every difference of the shared
timeline's pulse times. Groups in orders of their own have different differences, so they can
follow one another closer. This module searches such plans with a constraint solver (OR-Tools
CP-SAT) under the ceiling's terms, and the bus besides:

* the LSB at the settle path (``t_rst + t_settle`` and the group's block clears), each plane ``e``
  lit ``lsb << e``; a plane shorter than the reload (``t_rst + t_settle`` and the group's load)
  ends in a dark pulse and the next plane comes a reload after it; the frame's last plane ends in
  a dark pulse, and the group is loaded again a reload after it;
* every two pulses of the whole DMD at least ``t_rst`` apart (TI's reading: one RST_ACTIVE);
* one bus: each pulse takes a row cycle; each dark pulse's clears (``clear`` cycles) and each
  plane's rows (one load of ``load`` cycles: the group's rows at the row cycle, or at the
  memory's pace) begin once the group's pulse before them is ``t_rst + t_settle`` old and end by
  their own pulse; nothing on the bus overlaps, frames back to back (a frame's first loads run
  in the one before's tail);
* the facts table's timing without the sequencer's margins.

The solver's plan is checked by :func:`check`, which shares no code with it: it builds each
group's pulses with :func:`spec.schedule.timeline` and checks spacing, load windows and the bus
over two frames. The same search under the sequencer's own terms (:func:`sequencer_terms`: its
RST_ACTIVE with margin, hide threshold and dark gap) gives plans that :func:`played` hands to the
schedule model's sequencer (:func:`spec.schedule.simulate`, with each group's order and offset
from ``Params.group_tables`` and ``group_offsets``): its load queue as it is, row by row, which
says whether a pulse comes late and what period the sequencer would reach. A figure here is a
model's (``_model``: no gateware plays these plans; the sequencer's registers hold one order and
one stagger), beside the solver's proven lower bound on the frame.
"""

import math
from dataclasses import dataclass, replace

import numpy as np

from spec import ceiling, schedule
from spec.facts import DMDS
from spec.plan_search import order_kwargs
from spec.registers import PlaneOrder, ResetMode
from spec.schedule import FABRIC_HZ, beats_at, bound, even, groups, row_cycles, timeline

__all__ = ["Terms", "GroupPlan", "terms", "sequencer_terms", "solve", "check", "freeing", "played", "figures", "run"]


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


@dataclass
class GroupPlan:
    """A plan: each group's offset and plane order (weight exponents in display order), the
    frame (frames back to back), the start of each group's loads (one per plane, in display
    order) and of its clears (one per dark pulse but the frame's last), and the solver's proven
    lower bound on the frame."""
    terms: Terms
    frame: int
    offsets: list
    orders: list
    loads: list
    clears: list
    lower: int

    @property
    def rate_hz(self):
        return FABRIC_HZ / self.frame


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


def sequencer_terms(dmd, dclk_hz, reset_mode, **plan_kwargs):
    """The :class:`Terms` the sequencer keeps, and the one-timeline plan they come from
    (:func:`spec.schedule.plan`: its RST_ACTIVE with the sequencer's margin, its hide threshold
    and dark gap, its shortest LSB); ``plan_kwargs``: that function's (``words_per_cycle``,
    ``trigger_hold``, ...)."""
    base = schedule.plan(dmd, dclk_hz, reset_mode=reset_mode, **order_kwargs(PlaneOrder.TABLE, 8), **plan_kwargs)
    p = base.params
    assert p.hide == p.dark_gap, "a plane hides a load exactly when it is as long as a dark gap"
    t = terms(dmd, dclk_hz, reset_mode, row_period=p.row_period)
    # a load done the slack the spread search leaves it for other groups' pulses taking row cycles
    t = replace(t, lsb=even(base.lsb_min), reload=p.hide, t_rst=p.t_rst, t_settle=p.t_settle, slack=2 * t.row * t.G)
    return t, base


def played(dmd, found, base):
    """The schedule model's sequencer (:func:`spec.schedule.simulate`: its pulse-order load queue,
    row by row, dark clears first) playing ``found`` (a :class:`GroupPlan` in the
    :func:`sequencer_terms` of ``base``) from a trigger: the model's parameters, the pulses it
    makes late, and its trigger-to-trigger period."""
    q = replace(base.params, lsb=found.terms.lsb, group_tables=tuple(found.orders),
                group_offsets=tuple(found.offsets))
    frame = schedule.Frame(0, found.terms.depth)
    return q, schedule.simulate(dmd, q, [frame], [schedule.ready_cycle(dmd, q, frame)]).late, \
        schedule.frame_period(dmd, q, frame)


def solve(t, *, limit=None, seconds=60.0, workers=2, seed=0):
    """The fastest plan the solver finds within ``seconds`` (below ``limit`` frame cycles), or
    None. Each load may begin anywhere in its window (a scheduler by deadline could serve it so;
    the sequencer's queue serves loads in the order of the pulses that freed them). The search
    is parallel (``workers``): what it finds in a given time may differ from run to run; its
    lower bound is proved."""
    from ortools.sat.python import cp_model

    m = cp_model.CpModel()
    frozen = t.t_rst + t.t_settle
    lengths = [t.lsb << e for e in range(t.depth)]
    dark = [n < t.reload for n in lengths]
    span = sum(lengths) + t.reload * sum(dark)             # a group's planes, dark gaps included
    H = limit or 4 * (span + t.G * t.reload)
    F = m.new_int_var(0, H, "frame")
    rst, bus, keep = [], [], []

    def var(name, lo=-H, hi=3 * H):
        return m.new_int_var(lo, hi, name)

    def on_bus(start, size, name, present=None):
        # the interval and its copy a frame later: a periodic schedule
        for k in (0, 1):
            s = var(f"{name}@{k}")
            m.add(s == start + k * F)
            e = var(f"{name}@{k}e")
            bus.append(m.new_interval_var(s, size, e, name) if present is None else
                       m.new_optional_interval_var(s, size, e, present, name))

    def pulse(at, name, present=None):
        for k in (0, 1):
            s = var(f"{name}@{k}")
            m.add(s == at + k * F)
            rst.append(m.new_fixed_size_interval_var(s, t.t_rst, name) if present is None else
                       m.new_optional_fixed_size_interval_var(s, t.t_rst, present, name))
        on_bus(at, t.row, name + "/bus", present)

    N = t.depth                                             # the circuit's frame-boundary node
    for g in range(t.G):
        o = 2 * var(f"o{g}/2", 0, H // 2) if g else m.new_constant(0)     # even: decisions on even cycles
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
        m.add(F >= final + t.reload)
        loads, clears = [], []
        for e in range(N):
            m.add(s[e] == o).only_enforce_if(x[N, e])
            m.add(s[e] + occupied[e] == end).only_enforce_if(x[e, N])
            for a in range(N):
                if a != e:
                    m.add(s[e] == s[a] + occupied[a]).only_enforce_if(x[a, e])
            pulse(s[e], f"p{g}.{e}")
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
            m.add(ld + t.load + t.slack <= s[e])
            on_bus(ld, t.load, f"l{g}.{e}")
            loads.append(ld)
            if dark[e]:
                # its dark pulse, and the clears before it (the frame's last: at the end)
                pulse(s[e] + lengths[e], f"d{g}.{e}")
                c = var(f"c{g}.{e}", 0, H)
                m.add(c >= s[e] + frozen)
                m.add(c + t.clear <= s[e] + lengths[e])
                on_bus(c, t.clear, f"c{g}.{e}")
                clears.append((e, c))
        # the frame's last dark pulse when the last plane hides loads: it needs clears too
        pulse(end, f"f{g}", ~last_dark)
        c = var(f"cf{g}", 0, 2 * H)
        m.add(c + t.clear <= end)
        for a in range(N):
            m.add(c >= s[a] + frozen).only_enforce_if(x[a, N])
        on_bus(c, t.clear, f"cf{g}", ~last_dark)
        keep.append((o, s, loads, clears, c))
    m.add_no_overlap(rst)
    m.add_no_overlap(bus)
    m.minimize(F)
    solver = cp_model.CpSolver()
    solver.parameters.max_time_in_seconds = seconds
    solver.parameters.num_workers = workers
    solver.parameters.random_seed = seed
    if solver.solve(m) not in (cp_model.OPTIMAL, cp_model.FEASIBLE):
        return None
    v = solver.value
    offsets, orders, all_loads, all_clears = [], [], [], []
    for o, s, loads, clears, c in keep:
        order = sorted(range(N), key=lambda e: v(s[e]))
        offsets.append(v(o))
        orders.append(tuple(order))
        all_loads.append([v(loads[e]) for e in order])
        cl = {e: v(ce) for e, ce in clears}
        # clears in dark-pulse order, the frame's last dark pulse's last
        all_clears.append([cl[e] for e in order[:-1] if e in cl] + [cl.get(order[-1], v(c))])
    return GroupPlan(t, v(F), offsets, orders, all_loads, all_clears, math.ceil(solver.best_objective_bound))


def freeing(plan, g):
    """For each of group ``g``'s loads, in display order: the index of its plane's pulse in the
    group's timeline (:func:`spec.schedule.timeline`) and the time of the pulse that frees it
    (the group's pulse before: for the first plane, the frame before's last dark pulse)."""
    t = plan.terms
    times, darks = timeline(plan.orders[g], t.lsb, t.reload, t.reload)
    times = times + plan.offsets[g]
    return [(j, int(times[j - 1] if j else times[-1] - plan.frame))
            for j in range(len(times)) if j == 0 or not darks[j - 1]]


def check(plan):
    """What ``plan`` breaks (an empty list: nothing). Independent of the solver: each group's
    pulses from :func:`spec.schedule.timeline`, then over two frames back to back: every two
    pulses of the DMD ``t_rst`` apart, each load after its group's pulse before it plus ``t_rst +
    t_settle`` and done by its own pulse, each clear likewise before its dark pulse, the bus (a
    row cycle a pulse, the loads, the clears) never doing two things at once, every plane once."""
    t, F, bad = plan.terms, plan.frame, []
    frozen = t.t_rst + t.t_settle
    pulses, busy = [], []
    for g, (o, order) in enumerate(zip(plan.offsets, plan.orders, strict=True)):
        if sorted(order) != list(range(t.depth)):
            bad.append(f"group {g}: order {order} is not every plane once")
            continue
        times, darks = timeline(order, t.lsb, t.reload, t.reload)
        times = times + o
        if F < times[-1] + t.reload:
            bad.append(f"group {g}: not loaded again {t.reload} cycles after its last dark pulse")
        pulses += list(times)
        busy += [(int(p), t.row) for p in times]
        dark_at = [j + 1 for j in range(len(times) - 1) if darks[j]]
        for (j, before), ld in zip(freeing(plan, g), plan.loads[g], strict=True):
            if ld < before + frozen or ld + t.load + t.slack > times[j]:
                bad.append(f"group {g}: the load of plane {j} at {ld} outside [{before + frozen}, {times[j]}]")
            busy.append((ld, t.load))
        for j, c in zip(dark_at, plan.clears[g], strict=True):
            if c < times[j - 1] + frozen or c + t.clear > times[j]:
                bad.append(f"group {g}: the clears at {c} outside [{times[j - 1] + frozen}, {times[j]}]")
            busy.append((c, t.clear))
    both = np.sort(np.concatenate([np.array(pulses), np.array(pulses) + F]))
    if len(both) > 1 and np.diff(both).min() < t.t_rst:
        bad.append(f"two pulses {int(np.diff(both).min())} cycles apart, under t_rst {t.t_rst}")
    spans = sorted((s + k * F, n) for s, n in busy for k in (-1, 0, 1))
    for (s0, n0), (s1, _) in zip(spans, spans[1:], strict=False):
        if s0 + n0 > s1:
            bad.append(f"the bus busy at {s0} for {n0} cycles and again at {s1}")
            break
    return bad


def figures(*, seconds=120.0):
    """The dual reset mode on the DLP7000, at each DCLK with rows at the row cycle and at 400 MHz
    with rows at the pace of the system run (``make sim``: the DDR2 under GigE ingest): the
    fastest plan of groups in orders of their own the solver finds under the ceiling's terms,
    checked, against the bound, one timeline's ceiling and the frame the solver proved no plan of
    that kind beats; then one found under the sequencer's terms, played by the schedule model's
    sequencer (its load queue as it is), its period and pulses late."""
    from sim import xga

    out, dmd = {}, DMDS["dlp7000"]
    # the store's words a cycle: a row every row cycle (as the rates bench's store stand-in), or
    # the DDR2's read rate
    for dclk, words, key in ((200e6, beats_at(200e6), "200mhz"), (400e6, beats_at(400e6), "400mhz"),
                             (400e6, xga.read_rate(xga.McbTiming(), xga.DMD_HZ), "400mhz_ddr2")):
        top = ceiling.ceiling_of_mode(dmd, dclk, ResetMode.DUAL)
        seq_terms, base = sequencer_terms(dmd, dclk, ResetMode.DUAL, trigger_hold=True, words_per_cycle=words)
        pace = base.params.row_period
        found = solve(terms(dmd, dclk, ResetMode.DUAL, row_period=pace), seconds=seconds)
        bad = check(found)
        assert not bad, bad
        name = f"seq.gray8_group_orders_hz_dlp7000_dual_{key}"
        out[name + "_model"] = (found.rate_hz, "Hz")
        out[name.replace("_hz_", "_fraction_of_bound_") + "_model"] = (found.rate_hz / bound(dmd, dclk), "")
        out[name.replace("_hz_", "_hz_limit_") + "_model"] = (FABRIC_HZ / found.lower, "Hz")
        print(f"DLP7000, dual, {dclk / 1e6:g} MHz, rows every {pace} cycles: {found.rate_hz:.1f} Hz "
              f"({found.frame} cycles, {found.rate_hz / bound(dmd, dclk):.1%} of the bound; one timeline's ceiling "
              f"{top.rate_hz:.1f} Hz); no such plan beats {found.lower} cycles = {FABRIC_HZ / found.lower:.1f} Hz")
        for o, order in sorted(zip(found.offsets, found.orders, strict=True)):
            print(f"  offset {o:>6}  order {' '.join(map(str, order))}")
        # the LSB at the settle path leaves a dark pulse's clears no cycle to wait for a row under
        # way (the model serves loads as soon as it can): a row cycle or two more, if need be
        for extra in (0, 1, 2):
            seq = replace(seq_terms, lsb=seq_terms.lsb + extra * seq_terms.row)
            mine = solve(seq, seconds=seconds)
            assert not check(mine)
            _, late, period = played(dmd, mine, base)
            print(f"  under the sequencer's terms (RST_ACTIVE {seq.t_rst}, LSB {seq.lsb}, dark gap {seq.reload}), "
                  f"played by the schedule model's sequencer: {period} cycles = {FABRIC_HZ / period:.1f} Hz, "
                  f"{late} pulses late (its one-timeline plan: {base.rate_hz:.1f} Hz)")
            if not late:
                break
        out[name + "_sequencer_model"] = (FABRIC_HZ / period if not late else 0.0, "Hz")
        out[name + "_sequencer_lsb_model"] = (seq.lsb, "cycles")
    return out


def run():
    """``make bench``'s figures (:func:`figures`)."""
    return figures()


if __name__ == "__main__":
    for figure, (value, unit) in run().items():
        print(f"{figure:60s} {value:10.3f} {unit}")
