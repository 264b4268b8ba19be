"""System figures of the full-XGA run (:mod:`sim.xga`): simulation speed and the wall time of one
frame, from the ``make sim`` run (DLP7000, TI timing, default scene)."""

from sim import xga
from sim.system import XGA_FRAMES


def run():
    r = xga.run("bench", frames=XGA_FRAMES, log=lambda _text: None)
    assert all(f["max_error_lsb"] == 0 for f in r["frames"]), "the XGA run showed a wrong image"
    latencies = sorted(f["latency_cycles"] for f in r["frames"])
    return {
        "sys.xga_frame_sim_wall_s": (r["xga_frame_sim_wall_s"], "s"),
        "sys.sim_cycles_per_s": (r["dmd_cycles"] / r["sim_wall_s"], "dmd cycle/s"),
        "sys.xga_trigger_latency_cycles": (latencies[len(latencies) // 2], "cycle"),
        "sys.xga_trigger_latency_cycles_worst": (latencies[-1], "cycle"),
        "sys.xga_gray_error_lsb_max": (max(f["max_error_lsb"] for f in r["frames"]), "LSB"),
    }
