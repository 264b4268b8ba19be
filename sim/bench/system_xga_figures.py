"""System figures of the full-XGA run (:mod:`sim.rigs.xga_run`, what ``make sim`` runs): DLP7000, TI
timing, DCLK 400 MHz, the default scene stored as a sequence played by an entry table, one by one
then back to back: DCLK, the frame period measured on the pins, latency, grey error, simulation
speed. Beside it the streamed runs (:func:`streamed`): a new frame of the scene at every trigger.

``python -m sim.bench.system_xga_figures streamed`` prints the streamed runs' figures alone, ``.. binary`` the
binary patterns' from the store (:func:`binary_memory`)."""

from sim.rigs import xga_run as xga
from sim.rigs.system_run import XGA_BACK_TO_BACK, XGA_ENTRIES, XGA_FRAMES, XGA_ONE_BY_ONE, latency

#: Where a figure of the run ``name`` comes from (:mod:`flow.bench`).
XGA_SOURCE = ("gateware: the full-XGA system run (sim.rigs.xga_run, as make sim: the core's Verilog under Verilator, "
              "GMII in, MCB model, DLPC410 rule model and camera model out), {what}; run {name}")
PLAN_SOURCE = "model: the schedule model's period for the run's plan (spec.schedule), run {name}"


def run():
    r = xga.run("bench", frames=XGA_FRAMES, one_by_one=XGA_ONE_BY_ONE, back_to_back=XGA_BACK_TO_BACK,
                entries=XGA_ENTRIES, log=lambda _text: None)
    assert all(f["max_error_lsb"] == 0 for f in r["frames"]), "the XGA run showed a wrong image"
    typical, worst = latency(r["frames"])
    period = _median_period(r)
    run = XGA_SOURCE.format(what="DLP7000, the default scene", name="bench")
    return {
        "sys.xga_dclk_hz": (r["dclk_hz"], "Hz", run),
        "sys.xga_frame_period_cycles_measured": (period, "cycle", run + ", back-to-back frames on the pins"),
        "sys.xga_rate_hz_measured": (xga.DMD_HZ / period, "Hz",
                                     "arithmetic: 200 MHz / sys.xga_frame_period_cycles_measured"),
        "sys.xga_frame_period_cycles_model": (r["period_cycles"], "cycle", PLAN_SOURCE.format(name="bench")),
        "sys.xga_rate_hz_model": (r["rate_hz"], "Hz", PLAN_SOURCE.format(name="bench")),
        "sys.xga_frame_sim_wall_s": (r["xga_frame_sim_wall_s"], "s", run + ", wall time"),
        "sys.sim_cycles_per_s": (r["dmd_cycles"] / r["sim_wall_s"], "dmd cycle/s", run + ", wall time"),
        "sys.xga_trigger_latency_cycles": (typical, "cycle", run),
        "sys.xga_trigger_latency_cycles_worst": (worst, "cycle", run),
        "sys.xga_gray_error_lsb_max": (max(f["max_error_lsb"] for f in r["frames"]), "LSB", run),
        # the default scene over GigE: the first frame whole, the others as deltas of it (rows changed)
        "eth.scene_frames_per_s": (r["scene"]["delta_frames_per_s"], "frame/s", run + ", on the GMII pins"),
        "eth.scene_whole_frames_per_s": (r["scene"]["whole_frames_per_s"], "frame/s", run + ", on the GMII pins"),
        **faulty(),
        **dlp9500(),
        **streamed(),
        **binary_memory(),
    }


#: Frames of the streamed runs: as deltas (each of the first, a whole key frame), and whole.
STREAMED_FRAMES = {"delta": 6, "whole": 4}


def streamed():
    """A new frame at every trigger (:func:`sim.rigs.xga_run.stream`): the default scene streamed
    over GMII while triggers come at the plan's display rate (deltas: each frame the rows in which
    it differs from the first, a whole key frame), or at the pace GigE allows (whole frames). Every
    frame is shown once, in order, exact; the rate is measured between the first and the last
    frame's first clocking pulses on the pins."""
    figures = {}
    for kind, frames in STREAMED_FRAMES.items():
        name = f"bench-stream-{kind}"
        r = xga.stream(name, frames=frames, whole=kind == "whole", log=lambda _text: None)
        assert all(f["max_error_lsb"] == 0 and not f["equals_frames"] for f in r["frames"]), r["frames"]
        run = XGA_SOURCE.format(what=f"DLP7000, {frames} frames of the default scene streamed ({kind}), a trigger "
                                     f"every {r['trigger_period_cycles']} cycles, each frame new and exact", name=name)
        suffix = "" if kind == "delta" else "_whole"
        figures[f"sys.xga_new_frames_per_s_streamed{suffix}"] = (r["new_frames_per_s"], "frame/s",
                                                                  run + ", first pulses on the pins")
        figures[f"sys.xga_streamed{suffix}_trigger_period_cycles"] = (r["trigger_period_cycles"], "cycle", run)
        worst = max(f["latency_cycles"] for f in r["frames"])
        figures[f"sys.xga_streamed{suffix}_trigger_latency_cycles_worst"] = (worst, "cycle", run)
        # (a row that waited for its data while the next frame was written; no pulse late)
        for counter in ("row_underruns", "pulses_late", "triggers_held"):
            figures[f"sys.xga_streamed{suffix}_{counter}"] = (r["status"][counter], "count", run + ", status reply")
    return figures


def binary_memory():
    """Binary patterns from the store with the memory in the loop (:func:`sim.rigs.xga_run.binary_stream`):
    the core's plane reader and the MCB model feed the sequencer while GigE writes the next
    1-bit frame at line rate; every pattern exact and in order. The headline is the slowest
    pattern period while GigE wrote; beside it what the memory allows, worked out from the MCB
    timing model alone (its sustained bandwidth less the writes, over a pattern's bytes)."""
    from sim.models.mcb_model import McbTiming
    from sim.rigs.fast_system_rig import read_rate
    from spec import schedule
    name = "bench-binary"
    r = xga.binary_stream(name, log=lambda _text: None)
    during, status = r["periods_during_ingest"], r["status"]
    dmd, timing = xga.DMD, McbTiming()
    pattern_bytes = dmd.rows * dmd.columns / 8
    allowed = (timing.sustained_bytes_per_s - xga.BINARY_INGEST_BYTES_PER_S) / pattern_bytes
    mode = r["plan"].params.reset_mode.name.lower()
    run = XGA_SOURCE.format(what=f"DLP7000, 1-bit patterns chained from the store ({mode} reset), "
                                 f"{len(r['frames_shown'])} patterns of {xga.BINARY_FRAMES} frames, the later frames "
                                 f"sent over GMII at line rate while the patterns play, each pattern exact", name=name)
    allowed_source = ("model: the MCB timing model's sustained bandwidth (sim.models.mcb_model.McbTiming: peak x "
                      "efficiency, refresh taken off) less the store's writes of 1-bit frames at the GMII line rate "
                      "(sim.rigs.xga_run.BINARY_INGEST_BYTES_PER_S), over a DLP7000 pattern's bytes")
    words = read_rate(timing, xga.DMD_HZ, xga.BINARY_INGEST_BYTES_PER_S)
    return {
        "seq.binary_rate_hz_memory": (xga.DMD_HZ / max(during), "Hz",
                                      run + ", the slowest pattern period (block 0's pulses) while GigE wrote"),
        "seq.binary_rate_hz_memory_median": (xga.DMD_HZ / sorted(during)[len(during) // 2], "Hz",
                                             run + ", the median pattern period while GigE wrote"),
        "seq.binary_memory_periods_during_ingest": (len(during), "period", run),
        "seq.binary_memory_periods_off_plan": (sum(period != r["period_cycles"] for period in r["periods"]), "period",
                                               run + ", periods other than the plan's"),
        "seq.binary_memory_row_underruns": (status["row_underruns"], "row", run + ", status reply"),
        "seq.binary_memory_pulses_late": (status["pulses_late"], "pulse", run + ", status reply"),
        "seq.binary_memory_row_period_cycles_model": (r["plan"].params.row_period, "cycle",
                                                      f"model: the plan's row period (sim.rigs.xga_run.binary_plan), "
                                                      f"{words:.3f} words a cycle left to the reader"),
        "seq.binary_rate_hz_memory_model": (r["plan"].rate_hz, "Hz", PLAN_SOURCE.format(name=name)),
        "store.binary_rate_hz_allowed_model": (allowed, "Hz", allowed_source),
        "seq.binary_rate_memory_fraction_of_allowed_model": (
            xga.DMD_HZ / max(during) / allowed, "",
            "arithmetic: seq.binary_rate_hz_memory / store.binary_rate_hz_allowed_model"),
        "seq.binary_rate_memory_fraction_of_plan_model": (
            xga.DMD_HZ / max(during) / schedule.FABRIC_HZ * r["period_cycles"], "",
            "arithmetic: seq.binary_rate_hz_memory / seq.binary_rate_hz_memory_model"),
    }


def dlp9500():
    """The same run of the DLP9500's core (``make sim DMD=dlp9500``: four buses, 2048 columns
    sent, 1920 seen): the frame period measured on the pins, latency, grey error."""
    from spec.facts import DMDS
    r = xga.run("bench-dlp9500", frames=XGA_FRAMES, one_by_one=XGA_ONE_BY_ONE, back_to_back=XGA_BACK_TO_BACK,
                log=lambda _text: None, dmd=DMDS["dlp9500"])
    typical, worst = latency(r["frames"])
    run = XGA_SOURCE.format(what="the DLP9500's core, the default scene", name="bench-dlp9500")
    return {
        "sys.dlp9500_rate_hz_measured": (xga.DMD_HZ / _median_period(r), "Hz",
                                         run + ", back-to-back frames on the pins"),
        "sys.dlp9500_rate_hz_model": (r["rate_hz"], "Hz", PLAN_SOURCE.format(name="bench-dlp9500")),
        "sys.dlp9500_gray_error_lsb_max": (max(f["max_error_lsb"] for f in r["frames"]), "LSB", run),
        "sys.dlp9500_trigger_latency_cycles": (typical, "cycle", run),
        "sys.dlp9500_trigger_latency_cycles_worst": (worst, "cycle", run),
        "eth.dlp9500_scene_frames_per_s": (r["scene"]["delta_frames_per_s"], "frame/s", run + ", on the GMII pins"),
        "eth.dlp9500_scene_whole_frames_per_s": (r["scene"]["whole_frames_per_s"], "frame/s",
                                                 run + ", on the GMII pins"),
    }


def faulty():
    """The same run with the chips misbehaving (``make sim FAULTS=stalls`` and ``=all``,
    :data:`sim.rigs.xga_run.FAULTS`): every rule checked on the pins as always; the figures say what
    it cost. The RST_ACTIVE the projector measured is the plan's ``t_rst`` in ``all``."""
    figures = {}
    for kind in ("stalls", "all"):
        r = xga.run(f"bench-{kind}", frames=XGA_FRAMES, one_by_one=XGA_ONE_BY_ONE, back_to_back=XGA_BACK_TO_BACK,
                    faults=kind, log=lambda _text: None)
        status = r["status"]
        run = XGA_SOURCE.format(what=f"DLP7000, faults {kind} (sim.rigs.xga_run.FAULTS)", name=f"bench-{kind}")
        figures.update({
            f"sys.xga_faults_{kind}_gray_error_lsb_max": (max(f["max_error_lsb"] for f in r["frames"]), "LSB", run),
            f"sys.xga_faults_{kind}_rate_hz_measured": (xga.DMD_HZ / _median_period(r), "Hz",
                                                        run + ", back-to-back frames on the pins"),
            f"sys.xga_faults_{kind}_memory_stalls": (r["mcb_stalls"], "command", run),
            f"sys.xga_faults_{kind}_row_underruns": (status["row_underruns"], "row", run),
            f"sys.xga_faults_{kind}_pulses_late": (status["pulses_late"], "pulse", run),
            f"sys.xga_faults_{kind}_rst_active_late": (status["rst_active_late"], "pulse", run),
            f"sys.xga_faults_{kind}_t_rst_measured_cycles": (status["rst_active_cycles_max"], "cycle", run),
        })
    return figures


def _median_period(r):
    """The median of the back-to-back frame periods a run measured on the pins."""
    periods = sorted(r["periods_measured"])
    return periods[len(periods) // 2]


if __name__ == "__main__":
    import sys
    only = {"streamed": streamed, "faulty": faulty, "dlp9500": dlp9500, "binary": binary_memory}
    for figure, (value, unit, source) in (only[sys.argv[1]]() if sys.argv[1:] else run()).items():
        print(f"{figure:55s} {value:12.1f} {unit:10s} {source}")
