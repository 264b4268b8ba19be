"""System figures: the projector's core end to end (generated Verilog, small geometry).

Runs :func:`sim.rigs.system_run.run` (GMII in, MCB model, DLPC410 and camera models out) on the
default scene and reports what it measured. The full-XGA figures (``sys.sim_cycles_per_s``,
``sys.xga_frame_sim_wall_s``) are :mod:`sim.bench.system_xga_figures`'s.
"""

from sim.rigs import system_run as system

#: Where every figure here comes from (:mod:`flow.bench`).
SOURCE = ("gateware: the projector's core end to end (sim.rigs.system_run.run: generated Verilog under Verilator, "
          "small geometry, GMII in, MCB model, DLPC410 rule model and camera model out), the default scene")


def run():
    r = system.run("scene", scene=True)
    latencies = sorted(f["latency_cycles"] for f in r["frames"])
    return {
        "sys.trigger_latency_cycles": (latencies[len(latencies) // 2], "cycle"),
        "sys.trigger_latency_cycles_worst": (latencies[-1], "cycle"),
        "sys.frames_measured": (len(latencies), "frame"),
        "sys.gray_error_lsb_max": (max(f["max_error_lsb"] for f in r["frames"]), "LSB"),
        "sys.sim_cycles_per_s_test_dmd": (r["dmd_cycles"] / r["wall_s"], "dmd cycle/s"),
    }
