"""8-bit frame rates measured on the gateware, per reset mode and DCLK, at TI timing.

The sequencer's generated Verilog (:mod:`sim.rigs.seq_rig`: the store stand-in feeds a row at the
row cycle, two words a cycle at 400 MHz and four for the DLP9500, so these are the sequencer's and
the DLPC410's rates, not the DDR2's; ``make sim`` plays at the DDR2's pace) plays the ramp frame of
every grey level over and over, each trigger coming half a frame after the one before and held until
every group is ready (``trigger_hold``): the frames follow one another back to back. RST_ACTIVE and
settle are the facts table's (no scaling). The rule-checking DLPC410 model checks every cycle of the
pin trace, the commands must be the schedule model's cycle for cycle, and the camera model checks
every level of a frame between two others (global and phased: the next frame's trigger is obeyed
only once its last group has ended this one); the period is measured between the frames' first
pulses on the pins. Beside each measured rate, the schedule model's (``_model``). The DLP7000 in
every reset mode at 200 and 400 MHz, and the plan finder's choice (:mod:`spec.plan_search`) at each,
under TI's strict RST_ACTIVE reading and under the loose one beside it; the DLP9500 global at 400
MHz.

Plans beyond one timeline (:mod:`sim.bench.group_orders_figures`: dual reset's groups each in a
plane order of its own, from an offset of its own, found by a constraint solver) are measured the
same way at each DCLK; the headline ``seq.gray8_rate_hz_dlp7000`` is the faster of the two kinds at
200 MHz.

The ceiling of such plans (:func:`ceilings`, ``python -m sim.bench.rates_figures ceiling``): the
fastest rate any plan of one timeline for every group reaches (:mod:`spec.ceiling`), arithmetic
beside the measured rates, and the fraction of it the plan finder's choice reaches.

Binary patterns (:func:`binary`): 1-bit frames chained one after another on the full DLP7000 at
DCLK 400 MHz, from the on-chip pseudo-random source and from the store at the row period the
DDR2 leaves the plane reader in ``make sim``, global and phased: the period measured between
block 0's pulses over the last of several patterns, the commands the schedule model's cycle for
cycle, every rule checked; beside the memory rates, what that row period allows (a full load
back to back: ``rows * row_period`` cycles a pattern).
"""


from gateware.dlpc410.trigger import PIN_TO_STROBE
from sim.bench import group_orders_figures as group_orders
from sim.bench.rig_rate import FRAMES, RIG_SOURCE, measured_rate, median_period, ready, same_as_model
from sim.bench.seq_figures import BOUND_SOURCE, PLAN_SOURCE, bound_figure
from sim.rigs.seq_rig import run_rig
from spec import ceiling, plan_search, schedule
from spec.facts import DMDS
from spec.registers import ResetMode, Source

__all__ = ["measured_rate", "FRAMES", "run", "cases", "best", "ceilings", "binary", "binary_period", "CASES"]

#: (DMD, reset mode, strict RST_ACTIVE reading, DCLK, settle reading): the plans measured.
CASES = [
    *[("dlp7000", mode, strict, dclk, "ti") for dclk in (200e6, 400e6)
      for mode, strict in (("GLOBAL", True), ("QUAD", True), ("DUAL", True), ("SINGLE", False),
                           ("QUAD", False))],
    ("dlp9500", "GLOBAL", True, 400e6, "ti"),
    ("dlp9500", "QUAD", True, 400e6, "ti"),
    # the four-DMD paper's settle reading (loads while the mirrors settle), to compare like with like
    ("dlp9500", "GLOBAL", True, 400e6, "paper"),
]
def _alias(figures, name):
    """The figure ``name`` again under another name: its value and unit, arithmetic."""
    return figures[name][0], figures[name][1], f"arithmetic: equal to {name}"


def _larger(figures, a, b):
    """The larger of the figures ``a`` and ``b``, arithmetic."""
    return max(figures[a][0], figures[b][0]), figures[a][1], f"arithmetic: the larger of {a} and {b}"


def run():
    measured = {}
    figures = cases(measured)
    figures.update(best(measured))
    figures.update(ceilings(figures))
    figures.update(group_orders.figures())
    # the headline: the fastest legal plan measured at 200 MHz under TI's rules, of one timeline
    # (the plan finder's) or of groups in orders of their own (the solver's), frames that do not
    # overlap (a window holds each whole frame); chained phased frames overlap (a group starts
    # the next while another ends this one), so they are beside it, not in it
    figures["seq.gray8_rate_hz_dlp7000"] = _larger(figures, "seq.gray8_rate_hz_dlp7000_best_200mhz",
                                                   "seq.gray8_rate_hz_dlp7000_dual_200mhz_group_orders")
    figures["seq.gray8_rate_hz_dlp7000_chained"] = _alias(figures,
                                                          "seq.gray8_rate_hz_dlp7000_dual_200mhz_group_orders_chained")
    figures.update(binary())
    return figures


def ceilings(measured=None):
    """The ceiling of one-timeline plans on the DLP7000 (:mod:`spec.ceiling`: every plane order,
    LSB and stagger, loads assumed free) at each DCLK under each RST_ACTIVE reading, arithmetic
    (``_model``); with the plan finder's measured rates in ``measured``, the fraction of the
    ceiling each reaches."""
    figures, dmd = {}, DMDS["dlp7000"]
    for dclk in (200e6, 400e6):
        for strict in (True, False):
            key = f"{int(dclk / 1e6)}mhz" + ("" if strict else "_loose")
            top, each = ceiling.ceiling(dmd, dclk, strict_rst=strict)
            ceiling_name = f"seq.gray8_ceiling_hz_dlp7000_{key}_model"
            figures[ceiling_name] = (top.rate_hz, "Hz", "model: the ceiling of one-timeline plans (spec.ceiling), "
                                     f"{'strict' if strict else 'loose'} RST_ACTIVE reading")
            print(f"ceiling, DLP7000 at {dclk / 1e6:g} MHz, {'strict' if strict else 'loose'} RST_ACTIVE: "
                  f"{top.rate_hz:.1f} Hz, {top.rate_hz / schedule.bound(dmd, dclk):.1%} of the bound")
            for mode, c in each.items():
                print(f"  {mode.name:6} " + ("not above global" if c is None else
                      f"{c.rate_hz:6.1f} Hz  {c.frame_cycles:>7} cycles  order {' '.join(map(str, c.order))}  "
                      f"LSB {c.lsb}  stagger {c.stagger}"))
            rate = (measured or {}).get(f"seq.gray8_rate_hz_dlp7000_best_{key}")
            if rate is not None:
                figures[f"seq.gray8_fraction_of_ceiling_dlp7000_best_{key}_model"] = (
                    rate[0] / top.rate_hz, "", f"arithmetic: seq.gray8_rate_hz_dlp7000_best_{key} / {ceiling_name}")
    return figures


def cases(measured):
    """The :data:`CASES`, each played on the gateware; ``measured`` gets each (period, plan)."""
    figures = {}
    for dmd_name, mode, strict, dclk, reading in CASES:
        key = (f"{dmd_name}_{mode.lower()}{'' if strict else '_loose'}_{int(dclk / 1e6)}mhz"
               + ("_paper_timing" if reading == "paper" else ""))
        period, plan, error = measured_rate(dmd_name, mode, strict, dclk, reading, name=f"rates_{key}")
        assert error == 0, f"{key}: a frame not exact ({error} LSB)"
        measured[dmd_name, mode, strict, dclk, reading] = period, plan, error
        what = (f"{dmd_name} {mode.lower()}{'' if strict else ' loose'} at {dclk / 1e6:g} MHz, "
                f"{reading} settle reading")
        figures[f"seq.gray8_rate_hz_{key}"] = (schedule.FABRIC_HZ / period, "Hz",
                                              RIG_SOURCE.format(what=what, name=f"rates_{key}"))
        figures[f"seq.gray8_rate_hz_{key}_model"] = (plan.rate_hz, "Hz", f"{PLAN_SOURCE}, {what}")
        print(f"{key}: {schedule.FABRIC_HZ / period:.1f} Hz measured; binds: {plan.binds}")
    # the DLP9500 under TI's rules (its fastest reset mode) and under the paper's reading, with
    # the bounds and the paper's own arithmetic beside them
    dlp9500, clock = DMDS["dlp9500"], 400e6
    figures["seq.gray8_rate_hz_dlp9500"] = _larger(figures, "seq.gray8_rate_hz_dlp9500_global_400mhz",
                                                   "seq.gray8_rate_hz_dlp9500_quad_400mhz")
    figures[bound_figure(clock, "dlp9500")] = (schedule.bound(dlp9500, clock), "Hz", BOUND_SOURCE)
    figures["seq.gray8_rate_hz_dlp9500_paper_timing"] = _alias(figures,
                                                               "seq.gray8_rate_hz_dlp9500_global_400mhz_paper_timing")
    figures["seq.gray8_bound_hz_dlp9500_400mhz_paper_reading_model"] = (
        schedule.bound(dlp9500, clock, reading="paper"), "Hz",
        "model: the rate bound (spec.schedule.bound, docs/bounds.md) under the four-DMD paper's settle reading")
    figures["seq.gray8_rate_hz_dlp9500_paper_eq_model"] = (
        schedule.paper_eq_rate_hz(dlp9500, clock), "Hz",
        "model: the four-DMD paper's equations 6-7 (spec.schedule.paper_eq_rate_hz), the facts table's timing")
    return figures


def best(measured=None):
    """The plan finder's choice for the DLP7000 (every reset mode, plane order, hide threshold)
    at each DCLK, under TI's strict RST_ACTIVE reading and, ``_loose``, the loose one, played on
    the gateware (unless ``measured`` holds it already); the fraction of the bound each reaches."""
    figures, measured, errors = {}, measured or {}, []
    dmd = DMDS["dlp7000"]
    for dclk in (200e6, 400e6):
        for strict in (True, False):
            found = plan_search.find(dmd, dclk, trigger_hold=True, strict_rst=strict,
                                     words_per_cycle=schedule.row_rate_words(dmd, dclk))
            plan, mode = found.plan, found.best.reset_mode.name
            key = f"{int(dclk / 1e6)}mhz" + ("" if strict else "_loose")
            period, known, error = measured.get(("dlp7000", mode, strict, dclk, "ti"), (None, None, None))
            if known is None or known.params != plan.params:
                period, _, error = measured_rate("dlp7000", mode, strict, dclk, plan=plan,
                                                 name=f"rates_dlp7000_best_{key}")
            errors.append(error)
            print(f"plan finder, DLP7000 at {dclk / 1e6:g} MHz, {'strict' if strict else 'loose'} "
                  f"RST_ACTIVE: {found.binds}\n{found.table()}")
            rate = schedule.FABRIC_HZ / period
            what = (f"the plan finder's choice for the DLP7000 at {dclk / 1e6:g} MHz, "
                    f"{'strict' if strict else 'loose'} RST_ACTIVE reading ({mode.lower()})")
            run_name = (f"rates_dlp7000_{mode.lower()}{'' if strict else '_loose'}_{int(dclk / 1e6)}mhz"
                        if known is not None and known.params == plan.params else f"rates_dlp7000_best_{key}")
            figures[f"seq.gray8_rate_hz_dlp7000_best_{key}"] = (rate, "Hz", RIG_SOURCE.format(what=what, name=run_name))
            figures[f"seq.gray8_rate_hz_dlp7000_best_{key}_model"] = (
                plan.rate_hz, "Hz", f"model: {what} (spec.plan_search.find), schedule model")
            figures[f"seq.gray8_fraction_of_bound_dlp7000_best_{key}_model"] = (
                rate / schedule.bound(dmd, dclk), "",
                f"arithmetic: seq.gray8_rate_hz_dlp7000_best_{key} / {bound_figure(dclk)}")
    # the camera's error over a frame played back to back at each best plan
    figures["seq.gray_error_lsb_max_at_best_rate"] = (
        max(errors), "LSB", "gateware: the camera model's largest error on a frame between two others in each "
                            "seq.gray8_rate_hz_dlp7000_best_* run (rates rig)")
    return figures


#: Binary patterns played back to back (the period is the median of the last ones).
PATTERNS = 8


def binary_period(plan, name, *, patterns=PATTERNS):
    """Play 1-bit frames of ``plan`` (``chain``: each follows the one before without a trigger)
    on the DLP7000's generated Verilog from one trigger; returns the measured cycles between
    patterns (block 0's pulses)."""
    dmd, p = DMDS["dlp7000"], plan.params
    frames = [] if p.source == Source.PRNG else [(0, 1)]
    model_frames = [schedule.Frame(0, 1)]
    pins = [ready(dmd, p, model_frames) - PIN_TO_STROBE]
    cycles = pins[0] + PIN_TO_STROBE + (patterns + 2) * plan.frame_cycles
    run = run_rig(dmd, p, frames, pins=pins, cycles=cycles, name=name)
    starts = [t for t, kind, blocks in run.commands if kind == "pulse" and 0 in blocks]
    assert len(starts) >= patterns, f"{len(starts)} patterns played"
    same_as_model(dmd, p, model_frames, pins, cycles, run, name)
    return median_period(starts[-patterns:])


def binary():
    """Binary pattern rates on the DLP7000 at DCLK 400 MHz, measured on the sequencer rig: the
    on-chip source, and rows at the DDR2's row period from a stand-in that paces itself at that
    period (no memory in the loop: :func:`sim.bench.system_xga_figures.binary_memory` measures the store's
    rate with the memory model and GigE ingest), global and phased (quad: four blocks a pulse, TI's
    strict RST_ACTIVE reading; single: one block a pulse, the loose reading, beside it)."""
    from sim.models.mcb_model import McbTiming
    from sim.rigs.fast_system_rig import read_rate
    from sim.rigs.xga_run import plan as xga_plan
    dmd, dclk = DMDS["dlp7000"], 400e6
    # the read bandwidth the memory leaves the plane reader under GigE ingest, as make sim plans
    memory = {"words_per_cycle": read_rate(McbTiming(), schedule.FABRIC_HZ)}
    prng = {"source": Source.PRNG}
    plans = {
        "prng_global": prng,
        "prng_quad": {**prng, "reset_mode": ResetMode.QUAD},
        "prng_single_loose": {**prng, "reset_mode": ResetMode.SINGLE, "strict_rst": False},
        "memory_global": memory,
        "memory_quad": {**memory, "reset_mode": ResetMode.QUAD},
    }
    row_period = xga_plan(dclk).params.row_period
    allowed = schedule.FABRIC_HZ / (dmd.rows * row_period)
    figures = {
        "seq.binary_row_period_cycles_memory_model": (
            row_period, "cycle", "model: the system run's plan (sim.rigs.xga_run.plan) at DCLK 400 MHz, its row period "
                                 "from the MCB timing model's read rate under GigE ingest "
                                 "(sim.rigs.fast_system_rig.read_rate)"),
        # (the stand-in's own pace: a bound of the plan's, not of the memory's)
        "seq.binary_rate_hz_at_plan_row_period_model": (
            allowed, "Hz", "arithmetic: 200 MHz / (DLP7000 rows x seq.binary_row_period_cycles_memory_model)"),
    }
    for key, kwargs in plans.items():
        plan = schedule.plan(dmd, dclk, depth=1, chain=True, **kwargs)
        assert key.startswith("prng") or plan.params.row_period == row_period
        rate = schedule.FABRIC_HZ / binary_period(plan, f"rates_binary_{key}_400")
        figures[f"seq.binary_rate_hz_{key}_400mhz"] = (
            rate, "Hz", f"gateware: sequencer Verilog (sim.rigs.seq_rig), full DLP7000 at DCLK 400 MHz, 1-bit patterns "
                        f"chained from one trigger, block 0's pulses on the pins, commands equal to the schedule "
                        f"model's; run rates_binary_{key}_400")
        figures[f"seq.binary_rate_hz_{key}_400mhz_model"] = (plan.rate_hz, "Hz",
                                                             f"{PLAN_SOURCE}, {key.replace('_', ' ')}")
        if key.startswith("memory"):
            figures[f"seq.binary_rate_{key}_fraction_of_plan_row_period_model"] = (
                rate / allowed, "",
                f"arithmetic: seq.binary_rate_hz_{key}_400mhz / seq.binary_rate_hz_at_plan_row_period_model")
    # the headline figures: phased under TI's rules
    # (seq.binary_rate_hz_memory, the store's, is the system run's: sim.bench.system_xga_figures)
    figures["seq.binary_rate_hz_prng_400mhz"] = _alias(figures, "seq.binary_rate_hz_prng_quad_400mhz")
    return figures


if __name__ == "__main__":
    import sys
    only = {"binary": binary, "ceiling": ceilings, "best": best, "group_orders": group_orders.figures}
    for figure, (value, unit, *_source) in (only[sys.argv[1]]() if sys.argv[1:] else run()).items():
        print(f"{figure:50s} {value:10.1f} {unit}")
