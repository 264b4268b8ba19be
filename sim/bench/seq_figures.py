"""DLPC410 sequencer figures: trigger latency, 8-bit PWM rates, binary pattern rates.

Latencies are measured on the gateware in the Amaranth simulator (the small test DMD: the path from
the pin to the first clocking pulse does not depend on the geometry). Rates come from the schedule
model's plans for the DLP7000; the tests prove the gateware's command stream equal to the model's
cycle for cycle (``tests/test_dlpc410_sequencer.py`` on the test DMD in every reset mode,
``tests/test_dlpc410_sequencer_verilog.py`` on full XGA, global and single-block), and
:func:`gateware_binary_period` re-measures one rate on the gateware here. Each figure is given in
cycles or Hz at 200 MHz DCLK, and again at 400 MHz (``_400mhz``). Figures that come from the
schedule model (its plans' rates, frames, LSBs and staggers, the bound, the newer frame on XGA and
its reload on the test DMD) end in ``_model``; the measured rate of frames played back to back on
the gateware is ``sys.xga_rate_hz_measured`` (:mod:`sim.bench.system_xga_figures`).

Grey error (:func:`gray_error_table`): a global MSB-first 8-bit frame of the ramp image on the
DLP7000, played by the sequencer's generated Verilog (:mod:`sim.rigs.seq_rig`), its pins replayed
through the rule-checking DLPC410 model with the facts' RST_ACTIVE and settle times (so every
plan is also checked against every rule), and the camera model (4 us crossover ramp)
integrates a window as long as the frame's light (first pulse to the end of the last mirror
motion), shifted by a misalignment from the first pulse. LSB times from the shortest legal one
up to 16 times it; ``build/seq_gray_error.csv`` and ``build/seq_gray_error.png``.
``seq.gray_error_lsb_at_max_rate_phased``: the same at the fastest single-block plan (loose
RST_ACTIVE reading, the phased mode the cocotb test runs on XGA), window holding the frame.
"""

import numpy as np

from gateware.dlpc410.trigger import PIN_TO_STROBE
from sim.bench.tables import pyplot, write_table
from sim.harness.paths import build_dir
from sim.models.camera_model import Camera, to_lsb
from sim.rigs.seq_rig import run_rig
from sim.tb.plane_source import ramp_image
from sim.tb.seq_sim import run_bench
from spec import schedule
from spec.facts import DMDS, TEST_DMD
from spec.registers import ResetMode, Source

XGA = DMDS["dlp7000"]
#: DDR2 read bandwidth assumed to feed row loads in the model figures (the seed design's 1.3 GB/s).
DDR2_BYTES_PER_S = 1.3e9
FAST = {"t_rst_s": 20 / 200e6, "t_settle_s": 30 / 200e6}
#: Where the figures come from (:mod:`flow.bench`).
PLAN_SOURCE = "model: the schedule model's plan (spec.schedule.plan)"
BOUND_SOURCE = "model: the rate bound (spec.schedule.bound, docs/bounds.md), the facts table's timing"
LATENCY_SOURCE = ("gateware: sequencer, Amaranth simulator (sim.tb.seq_sim), test DMD, pins through the DLPC410 "
                  "rule model")
#: When the newer frame completes, by ``late``.
NEWER = {False: "while every group waits", True: "just after group 0's last pulse"}
GRAY_SOURCE = ("gateware: sequencer Verilog (sim.rigs.seq_rig), one triggered 8-bit frame of the ramp on the DLP7000 "
               "at the fastest legal {what} plan, pins through the DLPC410 rule model, light through the camera "
               "model; run {name}")


def bound_figure(dclk_hz, dmd="dlp7000"):
    """The name of the 8-bit rate bound's figure for ``dmd`` at DCLK ``dclk_hz``."""
    return f"seq.gray8_bound_hz_{dmd}{'' if dclk_hz == 200e6 else f'_{int(dclk_hz / 1e6)}mhz'}_model"


def trigger_latencies():
    """Pin edge to the first clocking pulse on the pins, in cycles, for pin edges on each
    phase of the DCLK/2 command grid, the first plane loaded and waiting."""
    p = schedule.plan(TEST_DMD, 200e6, depth=1, **FAST).params
    ready = max(g.loaded_at for g in schedule.simulate(TEST_DMD, p, [schedule.Frame(0, 1)]).groups)
    lat = []
    for phase in range(4):
        pin = ready + phase
        run = run_bench(TEST_DMD, p, [(0, 1)], pins=[pin], cycles=pin + 40, name=f"bench_latency_{phase}")
        pulse = next(t for t, kind, _a in run.commands if kind == "pulse")
        lat.append(pulse + 1 - pin)
    return lat


def newer_frame(dmd, p, *, late, gateware=False):
    """A newer frame completed just before the trigger: a trigger before its first plane is
    loaded again is an overrun, so the worst case is frame complete -> first clocking pulse of
    it on the pins, triggered as early as it is obeyed. ``late``: the frame completes one cycle
    after group 0's last pulse of the frame shown (the preload of its repeat is abandoned;
    the newer frame's load waits for the settle time of that pulse, or for the stale words to
    be discarded, whichever is later); else while every group waits. Returns (reload cycles:
    complete -> a trigger is obeyed, latency cycles, pin -> pulse cycles of that trigger); ``gateware``: measured on the
    gateware in the Amaranth simulator, else the schedule model (equal cycle for cycle)."""
    pin0 = max(g.loaded_at for g in schedule.simulate(dmd, p, [schedule.Frame(0, 1)]).groups)
    alone = schedule.simulate(dmd, p, [schedule.Frame(0, 1)], [pin0 + PIN_TO_STROBE])
    done = max(t for t, g, _k, _f, _e in alone.pulses if g == 0) + 1 if late \
        else max(g.loaded_at for g in alone.groups) + 10
    frames = [schedule.Frame(0, 1), schedule.Frame(1, 1, ready=done)]
    strobes = [pin0 + PIN_TO_STROBE]
    obeyed = max(g.loaded_at for g in schedule.simulate(dmd, p, frames, strobes).groups)
    pin = obeyed - PIN_TO_STROBE
    if gateware:
        run = run_bench(dmd, p, [(0, 1), (1, 1, done)], pins=[pin0, pin], cycles=pin + 40,
                        name=f"bench_newer_frame_{'late' if late else 'waiting'}")
        assert run.status["overruns"] == 0 and run.status["triggers"] == 2
        pulse = next(t for t, kind, _a in run.commands if kind == "pulse" and t >= pin)
    else:
        model = schedule.simulate(dmd, p, frames, strobes + [obeyed])
        assert model.overruns == 0 and [f.slot for f in model.shown] == [0, 1]
        pulse = next(t for t, _g, _k, fi, _e in model.pulses if fi == 1)
    return obeyed - done, pulse + 1 - done, pulse + 1 - pin


def dlp9500_figures(f, sfx):
    """Four buses (DLP9500, 1080p clears): the store gives one 64-bit word per cycle, a half
    (200 MHz) or a quarter (400 MHz) of a cycle's DLP9500 beats, so rows come every two or four
    row cycles (``row_period``); the same plans with rows at the row cycle
    (:func:`spec.schedule.row_rate_words`) show what that costs. The on-chip source needs no
    store."""
    d = DMDS["dlp9500"]
    row_rate = schedule.row_rate_words(d, f)
    gray = schedule.plan(d, f)
    mem = schedule.plan(d, f, depth=1, chain=True)
    return {
        f"seq.row_period_cycles_dlp9500_store{sfx}_model": (gray.params.row_period, "cycle", PLAN_SOURCE),
        f"seq.gray8_rate_hz_dlp9500_global{sfx}_model": (gray.rate_hz, "Hz", PLAN_SOURCE),
        f"seq.gray8_rate_hz_dlp9500_global_at_row_rate{sfx}_model": (
            schedule.plan(d, f, words_per_cycle=row_rate).rate_hz, "Hz", PLAN_SOURCE),
        bound_figure(f, "dlp9500"): (schedule.bound(d, f), "Hz", BOUND_SOURCE),
        f"seq.binary_rate_hz_memory_dlp9500{sfx}_model": (mem.rate_hz, "Hz", PLAN_SOURCE),
        f"seq.binary_rate_hz_memory_dlp9500_at_row_rate{sfx}_model": (
            schedule.plan(d, f, depth=1, chain=True, words_per_cycle=row_rate).rate_hz, "Hz", PLAN_SOURCE),
        f"seq.binary_rate_hz_prng_dlp9500{sfx}_model": (
            schedule.plan(d, f, depth=1, chain=True, source=Source.PRNG).rate_hz, "Hz", PLAN_SOURCE),
        f"seq.binary_rate_hz_prng_dlp9500_phased_loose{sfx}_model": (
            schedule.plan(d, f, depth=1, chain=True, source=Source.PRNG, reset_mode=ResetMode.SINGLE,
                          strict_rst=False).rate_hz, "Hz", PLAN_SOURCE),
    }


def gateware_binary_period():
    """Cycles between patterns of the Bernoulli source on the gateware (test DMD, phased):
    measured from the decoded pulses, and the model's figure."""
    plan = schedule.plan(TEST_DMD, 200e6, depth=1, chain=True, source=Source.PRNG,
                         reset_mode=ResetMode.SINGLE, strict_rst=False, **FAST)
    p = plan.params
    ready = max(g.loaded_at for g in schedule.simulate(TEST_DMD, p, [schedule.Frame(0, 1)]).groups)
    run = run_bench(TEST_DMD, p, [], pins=[ready - PIN_TO_STROBE], cycles=ready + 8 * p.lsb,
                    name="bench_binary_period")
    starts = [t for t, kind, blocks in run.commands if kind == "pulse" and 0 in blocks]
    return starts[-1] - starts[-2], plan.frame_cycles


#: LSB times of the grey-error sweep, as multiples of the shortest legal one.
LSB_FACTORS = (1, 1.5, 2, 4, 8, 16)
#: Camera window start minus the frame's first pulse, in microseconds.
MISALIGN_US = (-5, -1, 0, 1, 5, 20)
#: The misalignment of the ``seq.gray_error_rms_lsb_misaligned_<n>us`` figure.
MISALIGN_FIGURE_US = 1


def played_frame(plan, dclk, name):
    """One triggered frame of ``plan`` played by the sequencer's generated Verilog
    (:mod:`sim.rigs.seq_rig`, the store stand-in feeding rows at the DDR2's row rate for ``dclk``),
    its pins replayed through the rule-checking DLPC410 model: the model, the frame's first and last
    pulse cycles, and the image stored."""
    p = plan.params
    ready = max(g.loaded_at for g in schedule.simulate(XGA, p, [schedule.Frame(0, 8)]).groups)
    # on past the last pulse's mirror motion (a 4 us crossover) and beyond a window shifted late
    cycles = ready + plan.frame_cycles + round((10 + max(MISALIGN_US)) * 1e-6 * schedule.FABRIC_HZ)
    run = run_rig(XGA, p, [(0, 8)], pins=[ready - PIN_TO_STROBE], cycles=cycles,
                  store_words=schedule.row_rate_words(XGA, dclk), name=name)
    (first, last), = run.frames()
    return run.model, first, last, ramp_image(XGA, 0)


def gray_error_table(dclk=200e6):
    """Rows of (lsb cycles, frame cycles, rate Hz, misalignment us, max LSB, RMS LSB), each LSB
    time's frame played on the gateware."""
    words = schedule.row_rate_words(XGA, dclk)
    fastest = schedule.plan(XGA, dclk, words_per_cycle=words)
    rows = []
    for factor in LSB_FACTORS:
        plan = fastest if factor == 1 else schedule.plan(
            XGA, dclk, words_per_cycle=words, exposure_s=factor * fastest.params.lsb / schedule.FABRIC_HZ)
        model, first, last, image = played_frame(plan, dclk, f"bench_gray_error_{factor:g}")
        camera = Camera(model)
        span = last + camera.delay + camera.ramp - first
        for us in MISALIGN_US:
            t0 = first + round(us * 1e-6 * schedule.FABRIC_HZ)
            seen = to_lsb(camera.image(t0, t0 + span), plan.params.lsb)
            err = seen - image[:, :XGA.visible_columns]
            rows.append((plan.params.lsb, plan.frame_cycles, plan.rate_hz, us,
                         float(np.abs(err).max()), float(np.sqrt(np.mean(err ** 2)))))
    return rows


def write_gray_error(rows):
    """``build/seq_gray_error.csv`` and the plot ``build/seq_gray_error.png``."""
    write_table("seq_gray_error", ["lsb_cycles", "frame_cycles", "rate_hz", "misalign_us", "max_lsb", "rms_lsb"],
                [[r[0], r[1], f"{r[2]:.3f}", r[3], f"{r[4]:.4f}", f"{r[5]:.4f}"] for r in rows])
    plt = pyplot()
    out = build_dir()
    fig, axes = plt.subplots(1, 2, figsize=(10, 4), sharex=True)
    for us in MISALIGN_US:
        pts = [(r[1] / 200e3, r[4], r[5]) for r in rows if r[3] == us]
        period = [x[0] for x in pts]
        axes[0].plot(period, [x[1] for x in pts], "o-", label=f"{us:+g} us")
        axes[1].plot(period, [x[2] for x in pts], "o-", label=f"{us:+g} us")
    for ax, what in zip(axes, ("max", "RMS"), strict=True):
        ax.set_xscale("log")
        ax.set_yscale("symlog", linthresh=0.01)
        ax.set_ylim(bottom=0)
        ax.set_xlabel("frame period (ms, 200 MHz DCLK)")
        ax.set_ylabel(f"{what} grey error (LSB)")
        ax.grid(True, which="both", alpha=0.3)
    axes[1].legend(title="camera misalignment")
    fig.suptitle("DLP7000 8-bit global PWM: camera grey error against frame period")
    fig.tight_layout()
    fig.savefig(out / "seq_gray_error.png", dpi=100)
    plt.close(fig)


def gray_error_figures():
    rows = gray_error_table()
    write_gray_error(rows)
    lsb_min = min(r[0] for r in rows)
    at_max = [r for r in rows if r[0] == lsb_min]
    aligned = next(r for r in at_max if r[3] == 0)
    off = next(r for r in at_max if r[3] == MISALIGN_FIGURE_US)
    # phased (single-block pulses, loose RST_ACTIVE reading: the cocotb test's mode on XGA)
    phased = schedule.plan(XGA, 200e6, reset_mode=ResetMode.SINGLE, strict_rst=False,
                           words_per_cycle=schedule.row_rate_words(XGA, 200e6))
    model, first, last, image = played_frame(phased, 200e6, "bench_gray_error_phased")
    camera = Camera(model)
    seen = to_lsb(camera.image(first, last + camera.delay + camera.ramp), phased.params.lsb)
    fastest = GRAY_SOURCE.format(what="global", name="bench_gray_error_1")
    return {
        "seq.gray_error_lsb_at_max_rate_phased": (
            float(np.abs(seen - image[:, :XGA.visible_columns]).max()), "LSB",
            GRAY_SOURCE.format(what="single-block (loose RST_ACTIVE reading)", name="bench_gray_error_phased")),
        "seq.gray_error_lsb_at_max_rate": (aligned[4], "LSB", fastest),
        "seq.gray_error_rms_lsb_at_max_rate": (aligned[5], "LSB", fastest),
        f"seq.gray_error_rms_lsb_misaligned_{MISALIGN_FIGURE_US}us": (
            off[5], "LSB", f"{fastest}, camera window {MISALIGN_FIGURE_US} us late"),
        f"seq.gray_error_max_lsb_misaligned_{MISALIGN_FIGURE_US}us": (
            off[4], "LSB", f"{fastest}, camera window {MISALIGN_FIGURE_US} us late"),
        "seq.gray_error_rate_hz_at_max_rate_model": (aligned[2], "Hz", f"{PLAN_SOURCE}, the fastest global plan"),
    }


def run():
    figures = {}
    figures.update(gray_error_figures())
    lat = trigger_latencies()
    typical = sorted(lat)[len(lat) // 2]
    small = schedule.plan(TEST_DMD, 200e6, depth=1, **FAST).params
    newer = {late: newer_frame(TEST_DMD, small, late=late, gateware=True) for late in (False, True)}
    # the trigger that shows the newer frame; complete -> shown is the figure below
    worst = max(lat + [n[2] for n in newer.values()])
    figures["seq.trigger_latency_cycles_typical"] = (
        typical, "cycle", f"{LATENCY_SOURCE}, the median over a trigger pin on each phase (runs bench_latency_*)")
    figures["seq.trigger_latency_cycles_worst"] = (
        worst, "cycle", f"{LATENCY_SOURCE}, the largest over runs bench_latency_* and bench_newer_frame_*")
    for mhz in (200, 400):
        for which in ("typical", "worst"):
            cycles = f"seq.trigger_latency_cycles_{which}"
            figures[f"seq.trigger_latency_ns_{which}_at_{mhz}mhz"] = (
                figures[cycles][0] * 1e3 / mhz, "ns", f"arithmetic: {cycles} x {1e3 / mhz:g} ns")
    for late, (reload, shown, _pin) in newer.items():
        when = "late" if late else "waiting"
        # (the reload is the schedule model's: the earliest cycle it obeys the trigger; the gateware
        # is played with that trigger, which it obeys, and its pulse measured)
        figures[f"seq.newer_frame_reload_cycles_{when}_test_dmd_model"] = (
            reload, "cycle", "model: schedule model (spec.schedule.simulate), test DMD: frame complete to the "
                             "earliest trigger it obeys")
        figures[f"seq.newer_frame_to_pulse_cycles_{when}_test_dmd"] = (
            shown, "cycle", f"{LATENCY_SOURCE}, a newer frame completing {NEWER[late]}, triggered at "
                            f"seq.newer_frame_reload_cycles_{when}_test_dmd_model; run bench_newer_frame_{when}")
    xga = schedule.plan(XGA, 200e6, depth=1).params
    for late in (False, True):
        when = "late" if late else "waiting"
        reload, shown, _pin = newer_frame(XGA, xga, late=late)
        model = f"model: schedule model (spec.schedule.simulate), DLP7000, a newer frame completing {NEWER[late]}"
        figures[f"seq.newer_frame_reload_cycles_{when}_dlp7000_model"] = (reload, "cycle", model)
        figures[f"seq.newer_frame_to_pulse_cycles_{when}_dlp7000_model"] = (shown, "cycle", model)
        figures[f"seq.newer_frame_to_pulse_us_{when}_dlp7000_at_200mhz_model"] = (
            shown / 200, "us", f"arithmetic: seq.newer_frame_to_pulse_cycles_{when}_dlp7000_model x 5 ns")

    for mhz in (200, 400):
        f = mhz * 1e6
        sfx = "" if mhz == 200 else "_400mhz"
        # rows at the row cycle (the rates bench plays these plans: sim.bench.rates_figures)
        row_rate = {"words_per_cycle": schedule.row_rate_words(XGA, f)}
        glob = schedule.plan(XGA, f, **row_rate)
        quad = schedule.plan(XGA, f, reset_mode=ResetMode.QUAD, **row_rate)
        single_loose = schedule.plan(XGA, f, reset_mode=ResetMode.SINGLE, strict_rst=False, **row_rate)
        figures[f"seq.gray8_rate_hz_dlp7000_global{sfx}_model"] = (glob.rate_hz, "Hz", PLAN_SOURCE)
        figures[f"seq.gray8_frame_cycles_dlp7000_global{sfx}_model"] = (glob.frame_cycles, "cycle", PLAN_SOURCE)
        figures[f"seq.gray8_lsb_cycles_dlp7000_global{sfx}_model"] = (glob.params.lsb, "cycle", PLAN_SOURCE)
        figures[f"seq.gray8_rate_hz_dlp7000_phased{sfx}_model"] = (quad.rate_hz, "Hz", PLAN_SOURCE)
        figures[f"seq.gray8_lsb_cycles_dlp7000_phased{sfx}_model"] = (quad.params.lsb, "cycle", PLAN_SOURCE)
        figures[f"seq.gray8_stagger_cycles_dlp7000_phased{sfx}_model"] = (quad.params.stagger, "cycle", PLAN_SOURCE)
        dual = schedule.plan(XGA, f, reset_mode=ResetMode.DUAL, **row_rate)
        figures[f"seq.gray8_rate_hz_dlp7000_phased_dual{sfx}_model"] = (dual.rate_hz, "Hz", PLAN_SOURCE)
        figures[f"seq.gray8_rate_hz_dlp7000_phased_single_loose{sfx}_model"] = (single_loose.rate_hz, "Hz",
                                                                               PLAN_SOURCE)
        figures[bound_figure(f)] = (schedule.bound(XGA, f), "Hz", BOUND_SOURCE)

        prng = schedule.plan(XGA, f, depth=1, chain=True, source=Source.PRNG)
        prng_phased = schedule.plan(XGA, f, depth=1, chain=True, source=Source.PRNG,
                                    reset_mode=ResetMode.SINGLE, strict_rst=False)
        mem = schedule.plan(XGA, f, depth=1, chain=True, words_per_cycle=DDR2_BYTES_PER_S / 8 / f)
        mem_phased = schedule.plan(XGA, f, depth=1, chain=True, reset_mode=ResetMode.SINGLE, strict_rst=False,
                                   words_per_cycle=DDR2_BYTES_PER_S / 8 / f)
        figures[f"seq.binary_rate_hz_prng{sfx}_model"] = (prng.rate_hz, "Hz", PLAN_SOURCE)
        figures[f"seq.binary_rate_hz_prng_phased_loose{sfx}_model"] = (prng_phased.rate_hz, "Hz", PLAN_SOURCE)
        figures[f"seq.binary_rate_hz_memory{sfx}_model"] = (mem.rate_hz, "Hz", f"{PLAN_SOURCE}, DDR2 at 1.3 GB/s")
        figures[f"seq.binary_rate_hz_memory_phased_loose{sfx}_model"] = (mem_phased.rate_hz, "Hz",
                                                                        f"{PLAN_SOURCE}, DDR2 at 1.3 GB/s")
        figures.update(dlp9500_figures(f, sfx))

    measured, model = gateware_binary_period()
    figures["seq.binary_period_cycles_test_dmd_gateware"] = (
        measured, "cycle", "gateware: sequencer, Amaranth simulator (sim.tb.seq_sim), test DMD, on-chip source "
                           "phased, the last two patterns' block 0 pulses; run bench_binary_period")
    figures["seq.binary_period_cycles_test_dmd_model"] = (model, "cycle", PLAN_SOURCE)
    return figures


if __name__ == "__main__":
    for name, (value, unit, *_source) in run().items():
        print(f"{name:55s} {value:14.2f} {unit}")
