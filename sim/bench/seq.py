"""DLPC410 sequencer figures: trigger latency, 8-bit PWM rates, binary pattern rates.

Latencies are measured on the gateware in the Amaranth simulator (the small test DMD: the path
from the pin to the first clocking pulse does not depend on the geometry). Rates come from the
schedule model's plans for the DLP7000; the tests prove the gateware's command stream equal to
the model's cycle for cycle (``tests/test_dlpc410_sequencer.py`` on the test DMD in every reset
mode, ``tests/test_dlpc410_sequencer_verilog.py`` on full XGA, global and single-block), and
:func:`gateware_binary_period` re-measures one rate on the gateware here.
Each figure is given in cycles or Hz at 200 MHz DCLK, and again at 400 MHz (``_400mhz``).
"""

from gateware.dlpc410 import schedule
from gateware.dlpc410.facts import DMDS, TEST_DMD
from gateware.dlpc410.params import ResetMode, Source
from gateware.dlpc410.trigger import PIN_TO_STROBE
from sim.tb.seq_sim import run_bench

XGA = DMDS["dlp7000"]
#: DDR2 read bandwidth that feeds row loads (DLPC410.md "Derived bounds": 1.3 GB/s).
DDR2_BYTES_PER_S = 1.3e9
FAST = {"t_rst_s": 20 / 200e6, "t_settle_s": 30 / 200e6}


def trigger_latencies():
    """Pin edge to the first clocking pulse on the pins, in cycles, for pin edges on each
    phase of the DCLK/2 command grid, the first plane loaded and waiting."""
    p = schedule.plan(TEST_DMD, 200e6, depth=1, **FAST).params
    ready = max(g.loaded_at for g in schedule.simulate(TEST_DMD, p, [schedule.Frame(0, 1)]).groups)
    lat = []
    for phase in range(4):
        pin = ready + phase
        run = run_bench(TEST_DMD, p, [(0, 1)], pins=[pin], cycles=pin + 40, name=f"bench_latency_{phase}")
        pulse = next(t for t, kind, _a in run.decoder.commands if kind == "pulse")
        lat.append(pulse + 1 - pin)
    return lat


def newer_frame(dmd, p, *, late, gateware=False):
    """A newer frame completed just before the trigger: a trigger before its first plane is
    loaded again is an overrun, so the worst case is frame complete -> first clocking pulse of
    it on the pins, triggered as early as it is obeyed. ``late``: the frame completes one cycle
    after group 0's last pulse of the frame shown (its repeat is preloaded first, whole);
    else while every group waits. Returns (reload cycles: complete -> a trigger is obeyed,
    latency cycles, pin -> pulse cycles of that trigger); ``gateware``: measured on the
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
        pulse = next(t for t, kind, _a in run.decoder.commands if kind == "pulse" and t >= pin)
    else:
        model = schedule.simulate(dmd, p, frames, strobes + [obeyed])
        assert model.overruns == 0 and [f.slot for f in model.shown] == [0, 1]
        pulse = next(t for t, _g, _k, fi, _e in model.pulses if fi == 1)
    return obeyed - done, pulse + 1 - done, pulse + 1 - pin


def gateware_binary_period():
    """Cycles between patterns of the Bernoulli source on the gateware (test DMD, phased):
    measured from the decoded pulses, and the model's figure."""
    plan = schedule.plan(TEST_DMD, 200e6, depth=1, chain=True, source=Source.PRNG,
                         reset_mode=ResetMode.SINGLE, strict_rst=False, **FAST)
    p = plan.params
    ready = max(g.loaded_at for g in schedule.simulate(TEST_DMD, p, [schedule.Frame(0, 1)]).groups)
    run = run_bench(TEST_DMD, p, [], pins=[ready - PIN_TO_STROBE], cycles=ready + 8 * p.lsb,
                    name="bench_binary_period")
    starts = [t for t, kind, blocks in run.decoder.commands if kind == "pulse" and 0 in blocks]
    return starts[-1] - starts[-2], plan.frame_cycles


def run():
    figures = {}
    lat = trigger_latencies()
    typical = sorted(lat)[len(lat) // 2]
    small = schedule.plan(TEST_DMD, 200e6, depth=1, **FAST).params
    newer = {late: newer_frame(TEST_DMD, small, late=late, gateware=True) for late in (False, True)}
    # the trigger that shows the newer frame; complete -> shown is the figure below
    worst = max(lat + [n[2] for n in newer.values()])
    figures["seq.trigger_latency_cycles_typical"] = (typical, "cycle")
    figures["seq.trigger_latency_cycles_worst"] = (worst, "cycle")
    for mhz in (200, 400):
        figures[f"seq.trigger_latency_ns_typical_at_{mhz}mhz"] = (typical * 1e3 / mhz, "ns")
        figures[f"seq.trigger_latency_ns_worst_at_{mhz}mhz"] = (worst * 1e3 / mhz, "ns")
    for late, (reload, shown, _pin) in newer.items():
        when = "late" if late else "waiting"
        figures[f"seq.newer_frame_reload_cycles_{when}_test_dmd"] = (reload, "cycle")
        figures[f"seq.newer_frame_to_pulse_cycles_{when}_test_dmd"] = (shown, "cycle")
    xga = schedule.plan(XGA, 200e6, depth=1).params
    for late in (False, True):
        when = "late" if late else "waiting"
        reload, shown, _pin = newer_frame(XGA, xga, late=late)
        figures[f"seq.newer_frame_reload_cycles_{when}_dlp7000"] = (reload, "cycle")
        figures[f"seq.newer_frame_to_pulse_cycles_{when}_dlp7000"] = (shown, "cycle")
        figures[f"seq.newer_frame_to_pulse_us_{when}_dlp7000_at_200mhz"] = (shown / 200, "us")

    for mhz in (200, 400):
        f = mhz * 1e6
        sfx = "" if mhz == 200 else "_400mhz"
        glob = schedule.plan(XGA, f)
        quad = schedule.plan(XGA, f, reset_mode=ResetMode.QUAD)
        single_loose = schedule.plan(XGA, f, reset_mode=ResetMode.SINGLE, strict_rst=False)
        figures[f"seq.gray8_rate_hz_dlp7000_global{sfx}"] = (glob.rate_hz, "Hz")
        figures[f"seq.gray8_frame_cycles_dlp7000_global{sfx}"] = (glob.frame_cycles, "cycle")
        figures[f"seq.gray8_lsb_cycles_dlp7000_global{sfx}"] = (glob.params.lsb, "cycle")
        figures[f"seq.gray8_rate_hz_dlp7000_phased{sfx}"] = (quad.rate_hz, "Hz")
        figures[f"seq.gray8_rate_hz_dlp7000_phased_single_loose{sfx}"] = (single_loose.rate_hz, "Hz")
        figures[f"seq.gray8_bound_hz_dlp7000{sfx}"] = (schedule.bound(XGA, f), "Hz")

        prng = schedule.plan(XGA, f, depth=1, chain=True, source=Source.PRNG)
        prng_phased = schedule.plan(XGA, f, depth=1, chain=True, source=Source.PRNG,
                                    reset_mode=ResetMode.SINGLE, strict_rst=False)
        mem = schedule.plan(XGA, f, depth=1, chain=True, words_per_cycle=DDR2_BYTES_PER_S / 8 / f)
        mem_phased = schedule.plan(XGA, f, depth=1, chain=True, reset_mode=ResetMode.SINGLE, strict_rst=False,
                                   words_per_cycle=DDR2_BYTES_PER_S / 8 / f)
        figures[f"seq.binary_rate_hz_prng{sfx}"] = (prng.rate_hz, "Hz")
        figures[f"seq.binary_rate_hz_prng_phased_loose{sfx}"] = (prng_phased.rate_hz, "Hz")
        figures[f"seq.binary_rate_hz_memory{sfx}"] = (mem.rate_hz, "Hz")
        figures[f"seq.binary_rate_hz_memory_phased_loose{sfx}"] = (mem_phased.rate_hz, "Hz")

    measured, model = gateware_binary_period()
    figures["seq.binary_period_cycles_test_dmd_gateware"] = (measured, "cycle")
    figures["seq.binary_period_cycles_test_dmd_model"] = (model, "cycle")
    return figures


if __name__ == "__main__":
    for name, (value, unit) in run().items():
        print(f"{name:55s} {value:14.2f} {unit}")
