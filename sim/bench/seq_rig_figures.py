"""Sequencer rig figures (:mod:`sim.rigs.seq_rig`), per geometry: the time to build the rig from
nothing, the simulation's speed, and the speed of a whole run (the stimulus files, the
simulation, the trace replayed through the rule-checking model).

The run is one triggered 8-bit global frame of the ramp image (RST_ACTIVE and settle scaled
down as in the tests), to the end of its last pulse; the speeds count every clock cycle
simulated, initialisation included. The build goes to a build key of its own,
emptied first; its time is the first run's wall time less the second's (the same run on the
finished build).
"""

import shutil
import time

from gateware.dlpc410.trigger import PIN_TO_STROBE
from sim.harness.paths import build_dir, slug
from sim.rigs.seq_rig import TOPLEVEL, rig_verilog, run_rig
from spec import schedule
from spec.facts import DMDS, TEST_DMD, TEST_DMD4

GEOMETRIES = {"test": TEST_DMD, "test4": TEST_DMD4, "dlp7000": DMDS["dlp7000"]}


def frame_run(dmd, key):
    """One triggered frame on the rig: its wall time, and the run."""
    p = schedule.plan(dmd, 200e6, t_rst_s=40 / 200e6, t_settle_s=80 / 200e6).params
    frames = [schedule.Frame(0, 8)]
    pin = max(g.loaded_at for g in schedule.simulate(dmd, p, frames).groups) + 6
    cycles = schedule.simulate(dmd, p, frames, [pin + PIN_TO_STROBE]).commands[-1][0] + 64
    start = time.monotonic()
    run = run_rig(dmd, p, [(0, 8)], pins=[pin], cycles=cycles, name=f"bench_{key}", key=key)
    assert run.status["frames"] == 1 and run.status["late"] == 0
    return time.monotonic() - start, run


def run():
    figures = {}
    for name, dmd in GEOMETRIES.items():
        key = f"bench-{slug(dmd.name)}"
        shutil.rmtree(build_dir("cocotb", f"{TOPLEVEL}-{key}"))
        start = time.monotonic()
        rig_verilog(dmd)
        convert = time.monotonic() - start
        first, _ = frame_run(dmd, key)
        second, again = frame_run(dmd, key)
        source = f"gateware: sequencer rig (sim.rigs.seq_rig), {name} geometry, one triggered 8-bit frame, wall time"
        figures[f"seq_rig.convert_s_{name}"] = (convert, "s", f"{source} of its Verilog generation")
        figures[f"seq_rig.build_s_{name}"] = (first - second, "s", f"{source}: the first run's less the second's")
        figures[f"seq_rig.sim_cycles_per_s_{name}"] = (again.report["cycles"] / again.report["wall_s"], "dmd cycle/s",
                                                       f"{source} of the simulation")
        figures[f"seq_rig.run_cycles_per_s_{name}"] = (again.report["cycles"] / second, "dmd cycle/s",
                                                       f"{source} of the whole run")
    figures.update(trigger_pace())
    return figures


def trigger_pace(frames=16, seed=5):
    """A periodic trigger exactly at the back-to-back frame rate on the test DMD (the rig: the
    generated Verilog), newer frames completing at random phases of it (seeded): triggers lost
    (overruns) and delayed (held) on the gateware; the same run in the schedule model without the
    rule that a newer frame never delays a steady trigger, for comparison (``_model``)."""
    import numpy as np

    from spec.registers import TriggerMode
    plan = schedule.plan(TEST_DMD, 200e6, depth=3, t_rst_s=20 / 200e6, t_settle_s=30 / 200e6)
    p = plan.params
    p.trigger, p.trigger_hold, p.period = TriggerMode.PERIODIC, True, plan.frame_cycles
    rng = np.random.default_rng(seed)
    offered = [(0, 3, 0)] + [(k % 2, 3, int((k + rng.random()) * p.period)) for k in range(1, frames)]
    strobes = [k * p.period - 1 for k in range(1, frames)]
    until = strobes[-1] + p.period // 2
    run = run_rig(TEST_DMD, p, offered, cycles=until, name="bench_trigger_pace")
    unguarded = schedule._Model(TEST_DMD, p, [schedule.Frame(s, d, None, r) for s, d, r in offered], strobes)
    unguarded.fits = lambda t: True
    before = unguarded.run(until=until)
    rig = ("gateware: sequencer Verilog (sim.rigs.seq_rig), test DMD, a periodic trigger at the frame rate, newer "
           "frames at random phases; run bench_trigger_pace")
    unguarded_source = "model: schedule model (spec.schedule) without the steady-trigger rule, the same triggers"
    return {
        "seq.triggers_at_frame_rate": (len(strobes), "trigger", rig),
        "seq.triggers_lost_at_frame_rate": (len(strobes) - run.status["triggers"], "trigger", rig),
        "seq.triggers_delayed_at_frame_rate": (run.status["held"], "trigger", rig),
        "seq.triggers_lost_at_frame_rate_unguarded_model": (before.overruns, "trigger", unguarded_source),
        "seq.triggers_delayed_at_frame_rate_unguarded_model": (before.held, "trigger", unguarded_source),
    }


if __name__ == "__main__":
    for figure, (value, unit, *_source) in run().items():
        print(f"{figure:40s} {value:12.1f} {unit}")
