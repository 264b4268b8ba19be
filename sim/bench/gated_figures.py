"""Gated 8-bit frames: every plane the shortest legal time, the light source switched by the gate pin.

``seq.gray8_rate_hz_dlp7000_gated``: the gated plan (:func:`spec.schedule.plan_gated`) for the full
DLP7000 at DCLK 400 MHz (two beats), chained frames back to back on the sequencer's generated
Verilog (:mod:`sim.rigs.seq_rig`), the store stand-in feeding rows at the bus's pace (a row every
row cycle); the period read from the pins (the camera trigger's rises), the commands the schedule
model's cycle for cycle, the pins through the DLPC410 rule model. Beside it the largest grey error
of a frame between two others under the camera model (the mirrors' delay and crossover from the
facts table, the gate pin's waveform with the source's rise and fall), the pulses late, and the
gate edges not where the registers put them.

``sys.gray8_rate_hz_dlp7000_gated_memory`` (:func:`memory`): gated frames from the store, the
memory in the loop while GigE writes, on the core of ``make sim``.

``..._store_row_period``: the same with the rows paced at the store's row period (the row period
:func:`sim.rigs.fast_system_rig.read_rate` gives, held equal to the store's measured
``store.dlp7000_row_period_cycles_with_ingest`` by a test): a stand-in store paced at that row
period, not the memory in the loop.

The anchors: TI's 1.9 kHz and 2.89 kHz (:data:`spec.facts.ANCHORS`), and the binary bound: a
gated n-bit frame is n planes each at least a 1-bit pattern's period, so it cannot beat the binary
pattern rate over n (the plan's 1-bit chained rate at the same row pace).

The seed's camera experiment for a gated frame (:mod:`sim.bench.camera_figures`: a window leading
or lagging by 0-100 % of a frame): ``build/camera_misalignment_gated.csv`` and ``.png``.
"""

import numpy as np

from gateware.dlpc410.trigger import PIN_TO_STROBE
from sim.bench.camera_figures import worst_by_shift, write_one_curve
from sim.bench.rig_rate import median_period, ready, same_as_model
from sim.models.camera_model import Camera, to_lsb
from sim.models.mcb_model import McbTiming
from sim.rigs.fast_system_rig import read_rate
from sim.rigs.seq_rig import run_rig
from sim.tb.plane_source import ramp_image
from spec import schedule
from spec.facts import ANCHORS, DMDS, TEST_DMD, TIMING
from spec.registers import TriggerMode

__all__ = ["run", "played", "misalignment", "memory"]

XGA = DMDS["dlp7000"]
DCLK = 400e6
#: Frames played back to back (the period is the median of the last ones).
FRAMES = 4
#: The mirrors in the camera model: pulse to motion, and the crossover (the facts table's).
DELAY = round(TIMING["t_pulse_to_mirror"].value * schedule.FABRIC_HZ)
CROSSOVER = round(TIMING["t_crossover"].value * schedule.FABRIC_HZ)
#: Window start minus the ramp frame's first pulse, in % of the frame period (- leads, + lags).
SHIFTS_PCT = tuple(sorted({*range(-100, 101, 10), -1, 1}))

RIG = ("gateware: sequencer Verilog (sim.rigs.seq_rig), full DLP7000 at DCLK 400 MHz, the gated plan "
       "(spec.schedule.plan_gated) chained back to back, {pace}; pins through the DLPC410 rule model, commands "
       "equal to the schedule model's, camera model with the gate pin's light (run {name})")
BUS = "the store stand-in feeding a row every row cycle (the bus's pace)"
STORE = ("the store stand-in paced at the store's row period (sim.rigs.fast_system_rig.read_rate, equal to "
         "store.dlp7000_row_period_cycles_with_ingest): not the memory in the loop")
MODEL = "model: the schedule model's gated plan (spec.schedule.plan_gated), full DLP7000 at DCLK 400 MHz, {pace}"


def gate_light(run, dmd, first, last, p):
    """The camera's grey levels (in the least significant plane's light) over model cycles
    ``[first, last)``: the gate pin's waveform with the source's edges times the mirrors."""
    camera = Camera(run.model, ramp_cycles=CROSSOVER, delay_cycles=DELAY, visible=False,
                    gate=[(t - run.shift, level) for t, level in run.gate_out],
                    rise_cycles=schedule.LIGHT_RISE, fall_cycles=schedule.LIGHT_FALL)
    return to_lsb(camera.image(first, last), p.light_times[0])


def edges_off(run, p, until):
    """Gate edges on the pins not where the registers put them, against the schedule model's
    plane pulses (each gated plane's light ``light_lead`` after its pulse on the pins, for its
    ``light_times`` entry), up to ``until``."""
    model = schedule.simulate(XGA, p, [schedule.Frame(0, 8)], [ready(XGA, p, [schedule.Frame(0, 8)])],
                              until=until)
    want = []
    for t, _, kind, _, e in model.pulses:
        if kind == "plane":
            on = t + schedule.DECISION_TO_PINS + p.light_lead
            want += [(on, 1), (on + p.light_times[e], 0)]
    horizon = until - 2 * p.gated_time
    got = {edge for edge in run.gate_out if edge[0] < horizon}
    return len(got.symmetric_difference(edge for edge in want if edge[0] < horizon))


def played(words, name):
    """Gated chained frames back to back on the rig, rows paced for ``words`` store words a cycle:
    (period cycles, plan, grey error LSB, pulses late, gate edges off)."""
    plan = schedule.plan_gated(XGA, DCLK, words_per_cycle=words, chain=True)
    p = plan.params
    first = ready(XGA, p, [schedule.Frame(0, 8)])
    pins = [first - PIN_TO_STROBE]
    cycles = first + (FRAMES + 1) * plan.frame_cycles
    run = run_rig(XGA, p, [(0, 8)], pins=pins, cycles=cycles, store_words=schedule.row_rate_words(XGA, DCLK),
                  name=name)
    starts = [t - schedule.DECISION_TO_PINS - p.camera_offset for t, level in run.camera_out if level]
    assert len(starts) >= FRAMES, f"{len(starts)} frames played"
    same_as_model(XGA, p, [schedule.Frame(0, 8)], pins, cycles, run, name)
    # a frame between two others: from its first pulse on the pins to the next frame's
    first_pin, next_pin = (starts[k] + schedule.DECISION_TO_PINS - run.shift for k in (2, 3))
    error = float(np.abs(gate_light(run, XGA, first_pin, next_pin, p) - ramp_image(XGA, 0)).max())
    return median_period(starts), plan, error, run.status["late"], edges_off(run, p, cycles - run.shift)


def misalignment(shifts=SHIFTS_PCT, name="camera_gated"):
    """The seed's experiment on a gated frame (test DMD): black, the ramp, black, triggered at the
    frame rate; per shift (% of a frame), the mean error (LSB) of each grey level 0..255."""
    dmd = TEST_DMD
    plan = schedule.plan_gated(dmd, 200e6, t_rst_s=20 / 200e6, t_settle_s=30 / 200e6)
    p = plan.params
    p.trigger, p.trigger_hold, p.period = TriggerMode.PERIODIC, True, plan.frame_cycles
    rows, columns = np.indices((dmd.rows, dmd.columns))
    ramp = ((columns + 128 * (rows % 2)) & 255).astype(np.uint8)
    images = {0: np.zeros_like(ramp), 1: ramp}
    run = run_rig(dmd, p, [(slot, 8, 0, 1) for slot in (0, 1, 0)], images, cycles=4 * p.period, name=name)
    starts = [first for first, _last in run.frames()]
    assert len(starts) >= 3, f"three frames expected, got {len(starts)}"
    period = starts[2] - starts[1]
    out = {}
    for pct in shifts:
        t0 = starts[1] + round(pct * period / 100)
        error = gate_light(run, dmd, t0, t0 + period, p)[:, :dmd.visible_columns] - ramp
        out[pct] = np.array([error[ramp == g].mean() for g in range(256)])
    return out


def run():
    figures = {}
    paces = {"": (schedule.row_rate_words(XGA, DCLK), BUS),
             "_store_row_period": (read_rate(McbTiming(), schedule.FABRIC_HZ), STORE)}
    for sfx, (words, pace) in paces.items():
        name = f"gated_dlp7000{sfx}"
        period, plan, error, late, off = played(words, name)
        rig = RIG.format(pace=pace, name=name)
        model = MODEL.format(pace=pace)
        figures[f"seq.gray8_rate_hz_dlp7000_gated{sfx}"] = (schedule.FABRIC_HZ / period, "Hz", rig)
        figures[f"seq.gray8_gated_gray_error_lsb_max_dlp7000{sfx}"] = (error, "LSB", rig)
        figures[f"seq.gray8_gated_pulses_late_dlp7000{sfx}"] = (late, "pulse", rig)
        figures[f"seq.gray8_gated_gate_edges_off_dlp7000{sfx}"] = (off, "edge", rig)
        figures[f"seq.gray8_rate_hz_dlp7000_gated{sfx}_model"] = (plan.rate_hz, "Hz", model)
        figures[f"seq.gray8_gated_plane_cycles_dlp7000{sfx}_model"] = (plan.params.gated_time, "cycle", model)
        figures[f"seq.gray8_gated_row_period_cycles_dlp7000{sfx}_model"] = (plan.params.row_period, "cycle", model)
        figures[f"seq.gray8_gated_lsb_light_cycles_dlp7000{sfx}_model"] = (plan.params.light_times[0], "cycle",
                                                                            model)
        # the bound: a 1-bit pattern's chained rate at the same row pace, over 8
        binary = schedule.plan(XGA, DCLK, depth=1, chain=True, words_per_cycle=words)
        figures[f"seq.binary_rate_hz_dlp7000_global{sfx}_over_8_model"] = (
            binary.rate_hz / 8, "Hz", "model: the schedule model's 1-bit chained plan (spec.schedule.plan), global, "
                                      f"full DLP7000 at DCLK 400 MHz, {pace}, over 8 planes")
        gated = f"seq.gray8_rate_hz_dlp7000_gated{sfx}"
        for anchor, key in (("gray8_hz", "gated_gray8_dlp7000"), ("gray8_limit_hz", "gated_gray8_dlp7000_limit")):
            fact = ANCHORS[key]
            figures[f"seq.gray8_gated{sfx}_over_ti_{anchor}"] = (
                figures[gated][0] / fact.value, "1", f"arithmetic: {gated} / TI's {fact.value:g} Hz "
                                                     f"(spec.facts.ANCHORS {key})")
    figures.update(memory())
    curves = misalignment()
    write_one_curve("camera_misalignment_gated", curves, "gated, MSB first")
    cam = ("gateware: sequencer Verilog (sim.rigs.seq_rig), test DMD, the gated plan, three frames triggered at "
           "the frame rate; pins through the DLPC410 rule model, light through the camera model with the gate pin")
    for when, worst in worst_by_shift(curves).items():
        figures[f"cam.{when}_error_lsb_max_gated"] = (worst, "LSB", cam)
    return figures


def memory():
    """Gated frames from the store with the memory in the loop (:func:`sim.rigs.gated_run.gated_stream`):
    the core of ``make sim``, the gated plan set over GMII, its plane reader and the MCB model
    feeding the sequencer while GigE writes the next frame at line rate. The headline is the
    slowest frame period while GigE wrote; beside it the median, the plan's, and the bound at the
    memory's pace (:func:`spec.bounds.gated`)."""
    from sim.rigs import gated_run
    from spec import bounds
    name = "bench-gated"
    r = gated_run.gated_stream(name, log=lambda _text: None)
    during, status = r["periods_during_ingest"], r["status"]
    run = (f"gateware: the full-XGA system run's core (sim.rigs.gated_run, the build of make sim: Verilator, GMII in, "
           f"MCB model, DLPC410 rule model), DLP7000 at DCLK 400 MHz, the gated plan chained, {len(r['frames'])} "
           f"frames of {gated_run.FRAMES} sent, the later ones over GMII at line rate while the frames play, each "
           f"frame's light through the camera model with the gate pin; run {name}")
    rate = schedule.FABRIC_HZ / max(during)
    paces = bounds.Paces.of(XGA, DCLK, r["plan"].params.row_period)
    bound = bounds.gated(paces, 8)
    plan_source = (f"model: the gated plan's period (sim.rigs.gated_run.gated_plan, spec.schedule.plan_gated), "
                   f"run {name}")
    return {
        "sys.gray8_rate_hz_dlp7000_gated_memory": (rate, "Hz", run + ", the slowest frame period while GigE wrote"),
        "sys.gray8_rate_hz_dlp7000_gated_memory_median": (
            schedule.FABRIC_HZ / sorted(during)[len(during) // 2], "Hz",
            run + ", the median frame period while GigE wrote"),
        "sys.gray8_gated_memory_periods_during_ingest": (len(during), "period", run),
        "sys.gray8_gated_memory_periods_off_plan": (sum(period != r["period_cycles"] for period in r["periods"]),
                                                    "period", run + ", periods other than the plan's"),
        "sys.gray8_gated_memory_gray_error_lsb_max": (r["error_lsb_max"], "LSB", run),
        "sys.gray8_gated_memory_row_underruns": (status["row_underruns"], "row", run + ", status reply"),
        "sys.gray8_gated_memory_pulses_late": (status["pulses_late"], "pulse", run + ", status reply"),
        "sys.gray8_rate_hz_dlp7000_gated_memory_model": (r["plan"].rate_hz, "Hz", plan_source),
        "sys.gray8_gated_memory_bound_hz_model": (
            bound.rate_hz, "Hz", f"model: spec.bounds.gated, 8 bits, binds {bound.binds}, a row every "
                                 f"{paces.row_period} cycles (the run's plan's row period)"),
        "sys.gray8_gated_memory_fraction_of_bound_model": (
            rate / bound.rate_hz, "", "arithmetic: sys.gray8_rate_hz_dlp7000_gated_memory / "
                                      "sys.gray8_gated_memory_bound_hz_model"),
    }


if __name__ == "__main__":
    for figure, (value, unit, *_source) in run().items():
        print(f"{figure:60s} {value:12.3f} {unit}")
