"""Plans beyond one timeline (:mod:`spec.group_orders`: each group in a plane order of its own,
from an offset of its own, found by a constraint solver), checked and measured.

:func:`check` checks a solver's plan with code that shares nothing with the solver: it builds
each group's pulses with :func:`spec.schedule.timeline` and checks spacing, load windows and the
bus over two frames. :func:`figures` gives, on the DLP7000 in dual reset at each DCLK (rows at
the row cycle, and at the DDR2's pace of ``make sim``):

* the solver's plan under the facts table's terms, checked, against the bound, one timeline's
  ceiling and the frame the solver proved no plan of that kind beats (``_model``: arithmetic);
  the plan finder's LSB and, chained, its overlap (``_model``: the plan's);
* the plan finder's (:func:`spec.group_orders.find`: under the sequencer's own terms, played by
  the schedule model with no pulse late) measured on the gateware: the sequencer's generated
  Verilog plays the ramp frame back to back (:func:`sim.bench.rates_figures.measured_rate`: the rule
  model on every cycle, the commands the schedule model's cycle for cycle, every grey level of a
  frame between two others exact), the period between frames' first pulses on the pins;
* the same, chained (``_chained``: a stored sequence played without triggers, each group's
  next frame after its own; no group waits for the last to be loaded again, so a frame is a
  group's planes and one reload). Frames then overlap by the spread of the groups' offsets
  (``_overlap_cycles``: a group starts the next frame while another still shows this one); the
  camera's window is one period.
"""

import numpy as np

from sim.bench.rig_rate import RIG_SOURCE, measured_rate
from sim.bench.seq_figures import bound_figure
from sim.rigs import xga_run as xga
from spec import ceiling
from spec.facts import DMDS
from spec.group_orders import find, solve, terms
from spec.registers import ResetMode
from spec.schedule import FABRIC_HZ, beats_at, bound, timeline

__all__ = ["freeing", "check", "figures", "run"]


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
    row cycle a pulse, the loads, the clears) never doing two things at once, every plane once;
    triggered, the trigger (the terms' ``guard`` before group 0's first pulse) after every
    group's last dark pulse and every pulse's RST_ACTIVE, and after group 0's first load."""
    t, F, bad = plan.terms, plan.frame, []
    frozen = t.t_rst + t.t_settle
    pulses, busy = [], []
    for g, (o, order) in enumerate(zip(plan.offsets, plan.orders, strict=True)):
        if sorted(order) != list(range(t.depth)):
            bad.append(f"group {g}: order {order} is not every plane once")
            continue
        times, darks = timeline(order, t.lsb, t.reload, t.reload)
        times = times + o
        # (the next frame's first pulse: the group's own a frame on, chained, a reload after its
        # last dark pulse; else every group's offset after the next trigger, at the frame, which
        # may come once every group has made its last dark pulse: its load is checked below)
        if plan.chained and F + o < times[-1] + t.reload:
            bad.append(f"group {g}: not loaded again {t.reload} cycles after its last dark pulse")
        trigger = F - (0 if plan.chained else t.guard)
        if not plan.chained and trigger < times[-1]:
            bad.append(f"group {g}: its last dark pulse at {times[-1]} after the next trigger at {trigger}")
        if not plan.chained and t.guard and times.max() + t.t_rst > trigger:
            bad.append(f"group {g}: a pulse's RST_ACTIVE not over by the next trigger at {trigger}")
        pulses += list(times)
        busy += [(int(p), t.row) for p in times]
        dark_at = [j + 1 for j in range(len(times) - 1) if darks[j]]
        for (j, before), ld in zip(freeing(plan, g), plan.loads[g], strict=True):
            # (chained, the first plane's load is in the dark gap after the group's frame
            # before: the slack that gap leaves, not the one a load behind a plane keeps)
            slack = t.reload - frozen - t.load if plan.chained and j == 0 else t.slack
            if g == 0 and j == 0 and not plan.chained:
                slack = max(slack, t.guard)         # (loaded by the trigger)
            if ld < before + frozen or ld + t.load + slack > times[j]:
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
    fastest plan of groups in orders of their own the solver finds under the facts table's terms,
    checked, against the bound, one timeline's ceiling and the frame the solver proved no plan of
    that kind beats; then the plan finder's, under the sequencer's terms, measured on the
    gateware beside the model's period."""
    out, dmd = {}, DMDS["dlp7000"]
    # the store's words a cycle: a row every row cycle (as the rates bench's store stand-in), or
    # the DDR2's read rate
    for dclk, words, key in ((200e6, beats_at(200e6), "200mhz"), (400e6, beats_at(400e6), "400mhz"),
                             (400e6, xga.read_rate(xga.McbTiming(), xga.DMD_HZ), "400mhz_ddr2")):
        top = ceiling.ceiling_of_mode(dmd, dclk, ResetMode.DUAL)
        kwargs = {"trigger_hold": True, "words_per_cycle": words}
        chosen, _ = find(dmd, dclk, ResetMode.DUAL, seconds=seconds, **kwargs)
        pace = chosen.params.row_period
        found = solve(terms(dmd, dclk, ResetMode.DUAL, row_period=pace), seconds=seconds)
        bad = check(found)
        assert not bad, bad
        name = f"seq.gray8_group_orders_hz_dlp7000_dual_{key}"
        out[name + "_model"] = (found.rate_hz, "Hz", "model: the constraint solver's plan (spec.group_orders.solve) "
                                                     "under the facts table's terms, checked by check()")
        out[name.replace("_hz_", "_fraction_of_bound_") + "_model"] = (
            found.rate_hz / bound(dmd, dclk), "", f"arithmetic: {name}_model / {bound_figure(dclk)}")
        out[name.replace("_hz_", "_hz_limit_") + "_model"] = (
            FABRIC_HZ / found.lower, "Hz", "model: the frame the constraint solver proved no such plan beats")
        print(f"DLP7000, dual, {dclk / 1e6:g} MHz, rows every {pace} cycles: {found.rate_hz:.1f} Hz "
              f"({found.frame} cycles, {found.rate_hz / bound(dmd, dclk):.1%} of the bound; one timeline's ceiling "
              f"{top.rate_hz:.1f} Hz); no such plan beats {found.lower} cycles = {FABRIC_HZ / found.lower:.1f} Hz")
        for o, order in sorted(zip(found.trigger_offsets, found.orders, strict=True)):
            print(f"  offset {o:>6}  order {' '.join(map(str, order))}")
        # the plan finder's, on the gateware (the store stand-in at the row cycle; the sequencer
        # paces rows at the plan's row period)
        period, _, error = measured_rate("dlp7000", "DUAL", True, dclk, plan=chosen, name=f"group_orders_{key}")
        assert error == 0, f"{key}: a frame not exact ({error} LSB)"
        p = chosen.params
        print(f"  the plan finder's (RST_ACTIVE {p.t_rst}, LSB {p.lsb}, dark gap {p.dark_gap}): "
              f"{FABRIC_HZ / period:.1f} Hz measured on the gateware ({period} cycles), the model's "
              f"{chosen.rate_hz:.1f} Hz, {FABRIC_HZ / period / bound(dmd, dclk):.1%} of the bound")
        for o, order in sorted(zip(p.group_offsets, p.group_tables, strict=True)):
            print(f"  offset {o:>6}  order {' '.join(map(str, order))}")
        what = f"the plan finder's dual plan of group orders (spec.group_orders.find) at {dclk / 1e6:g} MHz"
        rate_name = name.replace("_group_orders_hz_", "_rate_hz_") + "_group_orders"
        out[rate_name] = (FABRIC_HZ / period, "Hz", RIG_SOURCE.format(what=what, name=f"group_orders_{key}"))
        out[rate_name + "_model"] = (chosen.rate_hz, "Hz", f"model: {what}, schedule model")
        out[name.replace("_group_orders_hz_", "_fraction_of_bound_") + "_group_orders_model"] = (
            FABRIC_HZ / period / bound(dmd, dclk), "", f"arithmetic: {rate_name} / {bound_figure(dclk)}")
        out[f"seq.gray8_group_orders_lsb_cycles_dlp7000_dual_{key}_model"] = (p.lsb, "cycles",
                                                                            f"model: {what}: its LSB")
        # chained (a stored sequence played without triggers): each group starts its next frame
        # as it ends this one, so no group waits for the last to be loaded again
        chained, groups = find(dmd, dclk, ResetMode.DUAL, seconds=seconds, chained=True, **kwargs)
        period, _, error = measured_rate("dlp7000", "DUAL", True, dclk, plan=chained,
                                         name=f"group_orders_{key}_chained")
        assert error == 0, f"{key}, chained: a frame not exact ({error} LSB)"
        overlap = max(chained.params.group_offsets)
        print(f"  chained, the plan finder's (LSB {chained.params.lsb}; the solver's frame {groups.frame} cycles, "
              f"each group's span): {FABRIC_HZ / period:.1f} Hz measured on the gateware "
              f"({period} cycles), the model's {chained.rate_hz:.1f} Hz, {FABRIC_HZ / period / bound(dmd, dclk):.1%} "
              f"of the bound; frames overlap by the offsets' spread, {overlap} cycles")
        for o, order in sorted(zip(chained.params.group_offsets, chained.params.group_tables, strict=True)):
            print(f"  offset {o:>6}  order {' '.join(map(str, order))}")
        chained_name = name.replace("_group_orders_hz_", "_rate_hz_") + "_group_orders_chained"
        what = f"the plan finder's chained dual plan of group orders (spec.group_orders.find) at {dclk / 1e6:g} MHz"
        out[chained_name] = (FABRIC_HZ / period, "Hz",
                             RIG_SOURCE.format(what=what, name=f"group_orders_{key}_chained"))
        out[chained_name + "_model"] = (chained.rate_hz, "Hz", f"model: {what}, schedule model")
        out[chained_name.replace("_rate_hz_", "_fraction_of_bound_") + "_model"] = (
            FABRIC_HZ / period / bound(dmd, dclk), "", f"arithmetic: {chained_name} / {bound_figure(dclk)}")
        out[f"seq.gray8_group_orders_chained_overlap_cycles_dlp7000_dual_{key}_model"] = (
            overlap, "cycles", f"model: {what}: its largest group offset")
    return out


def run():
    """``make bench``'s figures (:func:`figures`)."""
    return figures()


if __name__ == "__main__":
    for figure, (value, unit, *_source) in run().items():
        print(f"{figure:60s} {value:10.3f} {unit}")
