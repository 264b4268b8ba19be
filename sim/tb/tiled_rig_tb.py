"""cocotb stimulus of the tiled display rig (:class:`sim.rigs.tiled_rig.TiledRig`).

No Python per cycle and no cocotb clock: every clock is a Verilog oscillator. The testbench sets
the boards' registers and responders, waits for every board to be ready (initialised, its first
plane loaded), arms the master and then looks in once a frame period until the master has sent
its pulses; a frame period later (the last frame played out) it flushes the recorders and writes
the counters to the report. The figures are made afterwards from the recorded times.

Run through :func:`sim.rigs.tiled_rig.run_tiled` by ``tests/test_tiled_verilog.py`` and the sync
benchmark (:mod:`sim.bench.sync_figures`).
"""

import json
import time
from pathlib import Path

import cocotb
from cocotb.triggers import Timer

from sim.harness.cocotb_run import params


def _fields(dut, p, name, index):
    """Board ``index``'s element of the array port ``name``, unpacked by ``p[name]``'s fields."""
    value = getattr(dut, name).value.to_unsigned() >> (index * sum(width for _, _, width in p[name]))
    return {field: value >> offset & ((1 << width) - 1) for field, offset, width in p[name]}


@cocotb.test()
async def play(dut):
    p = params()
    wall = time.monotonic()
    dut.regs.value = p["regs"]
    dut.timing.value = p["timing"]
    for name in ("mode", "period", "min_period", "width"):
        getattr(dut, name).value = p[name]
    dut.run.value = 0
    dut.flush.value = 0
    everyone = (1 << p["boards"]) - 1
    step = p["period_ps"]
    waited = 0
    while dut.ready.value.to_unsigned() != everyone:
        await Timer(step // 10, "ps")
        waited += step // 10
        assert waited < p["max_ps"], "the boards never became ready"
    dut.run.value = 1
    while dut.pulses.value.to_unsigned() < p["frames"]:
        await Timer(step, "ps")
        waited += step
        assert waited < p["max_ps"], f"{dut.pulses.value.to_unsigned()} of {p['frames']} pulses sent in time"
    dut.run.value = 0
    await Timer(2 * step, "ps")
    dut.flush.value = 1
    await Timer(step // 10, "ps")
    dut.flush.value = 0
    await Timer(step // 10, "ps")
    Path(p["report"]).write_text(json.dumps({
        "status": [_fields(dut, p, "status", i) for i in range(p["boards"])],
        "loops": [_fields(dut, p, "loops", i) for i in range(p["boards"])],
        "counts": {name: getattr(dut, name).value.to_unsigned() for name in ("pulses", "not_ready", "early")},
        "wall_s": time.monotonic() - wall}))
