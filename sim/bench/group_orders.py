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
over two frames. A figure here is what the solver found within its time (``_model``: no
gateware plays these plans; the sequencer's registers hold one order and one stagger), beside
the solver's proven lower bound on the frame.
"""

import math
from dataclasses import dataclass

import numpy as np

from spec import ceiling
from spec.facts import DMDS
from spec.registers import ResetMode
from spec.schedule import FABRIC_HZ, beats_at, bound, even, groups, row_cycles, timeline

__all__ = ["Terms", "GroupPlan", "terms", "solve", "check", "freeing", "figures", "run"]


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
        o = var(f"o{g}", 0, H) if g else m.new_constant(0)
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
            m.add(ld + t.load <= s[e])
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
        all_clears.append([cl[e] for e in order if e in cl and not (e == order[-1])]
                          + ([cl[order[-1]]] if order[-1] in cl else [v(c)]))
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
            if ld < before + frozen or ld + t.load > times[j]:
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
    """The dual reset mode on the DLP7000: the fastest plan of groups in orders of their own the
    solver finds, checked, at each DCLK with rows at the row cycle and at 400 MHz with rows at the
    pace of the system run (``make sim``: the DDR2 under GigE ingest), against the bound, one
    timeline's ceiling and the frame the solver proved no plan of that kind beats."""
    from sim import xga

    out, dmd = {}, DMDS["dlp7000"]
    for dclk, pace, key in ((200e6, None, "200mhz"), (400e6, None, "400mhz"),
                            (400e6, xga.plan().params.row_period, "400mhz_ddr2")):
        top = ceiling.ceiling_of_mode(dmd, dclk, ResetMode.DUAL)
        plan = solve(terms(dmd, dclk, ResetMode.DUAL, row_period=pace), seconds=seconds)
        bad = check(plan)
        assert not bad, bad
        out[f"seq.gray8_group_orders_hz_dlp7000_dual_{key}_model"] = (plan.rate_hz, "Hz")
        out[f"seq.gray8_group_orders_fraction_of_bound_dlp7000_dual_{key}_model"] = (
            plan.rate_hz / bound(dmd, dclk), "")
        out[f"seq.gray8_group_orders_hz_limit_dlp7000_dual_{key}_model"] = (FABRIC_HZ / plan.lower, "Hz")
        print(f"DLP7000, dual, {dclk / 1e6:g} MHz, rows every {pace or plan.terms.row} cycles: {plan.rate_hz:.1f} Hz "
              f"({plan.frame} cycles, {plan.rate_hz / bound(dmd, dclk):.1%} of the bound; one timeline's ceiling "
              f"{top.rate_hz:.1f} Hz); no such plan beats {plan.lower} cycles = {FABRIC_HZ / plan.lower:.1f} Hz")
        for o, order in sorted(zip(plan.offsets, plan.orders, strict=True)):
            print(f"  offset {o:>6}  order {' '.join(map(str, order))}")
    return out


def run():
    """``make bench``'s figures (:func:`figures`)."""
    return figures()


if __name__ == "__main__":
    for figure, (value, unit) in run().items():
        print(f"{figure:60s} {value:10.3f} {unit}")
