"""cocotb stimulus of the sequencer rig (:class:`sim.rigs.seq_rig.SequencerRig`).

No Python per cycle: the clock is cocotb's, the tables and pin events come from files, the
DLPC410 responder and the pin recorder are Verilog. The testbench sets the registers, the seed
and the responder's timing, then plays a short script of steps, each one await on a timer or on
an edge of a port, and writes what it observed to the report; the checks are made afterwards on
the trace (:func:`sim.rigs.seq_rig.analyse`).

Run through :func:`sim.rigs.seq_rig.run_rig` by the sequencer's tests on its generated Verilog:
``tests/test_dlpc410_sequencer.py``, ``tests/test_dlpc410_sequencer_verilog.py``,
``tests/test_dlpc410_entries.py``, ``tests/test_dlpc410_ready.py``, ``tests/test_dlpc410_reload.py``
and ``tests/test_camera_misalignment.py``; and by the rate benchmarks.

Steps (the script's entries), written as the Amaranth testbench they replace would do them;
between steps the testbench stands in the middle of a cycle, where the cycle's values are
settled and an input set is sampled at the cycle's end:

``{"op": "until_now", "now": t}``
    Past the clock edge that ends the cycle on which the time base is ``t``.
``{"op": "until", "signal": name, "level": v}``
    ``await ctx.tick().until(name == v)``: at least one edge, up to the first edge that ends a
    cycle on which the port had that level.
``{"op": "wait_for", "signal": name, "level": v, "name": key}``
    ``while name != v: await ctx.tick()``; the edges it took are observed as ``key``.
``{"op": "ticks", "count": n}``
    ``n`` clock edges.
``{"op": "set", "signal": name, "value": v}``
    Drive an input from this cycle on.
``{"op": "observe", "name": key, "signals": [...]}``
    Record ports' values in this cycle (``status`` unpacked into its fields).
"""

import json
import time
from pathlib import Path

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import Edge, FallingEdge, RisingEdge, Timer, with_timeout

from sim.harness.cocotb_run import params

PERIOD_PS = 5000


class Rig:
    def __init__(self, dut, p):
        self.dut, self.p = dut, p
        self.observed = {}

    def status(self):
        value = self.dut.status.value.to_unsigned()
        return {name: value >> offset & ((1 << width) - 1) for name, offset, width in self.p["status"]}

    async def read(self, name):
        await Timer(1, "ps")                      # inputs set in this cycle have settled
        return self.status() if name == "status" else int(getattr(self.dut, name).value)

    async def ticks(self, count):
        if count > 0:
            await Timer(count * PERIOD_PS, "ps")

    async def reach(self, name, level):
        """Mid-cycle to the middle of the first cycle (this one included) with ``name == level``."""
        if await self.read(name) != level:
            await Edge(getattr(self.dut, name))   # just after the edge that changed it
            await FallingEdge(self.dut.clk)

    async def until_now(self, target):
        if not await self.read("running"):
            await RisingEdge(self.dut.running)
            await FallingEdge(self.dut.clk)
        await self.ticks(target - self.status()["now"] + 1)

    async def step(self, step):
        op = step["op"]
        if op == "until_now":
            await self.until_now(step["now"])
        elif op == "until":
            await self.reach(step["signal"], step["level"])
            await self.ticks(1)
        elif op == "wait_for":
            before = self.cycles()
            await self.reach(step["signal"], step["level"])
            self.observed[step["name"]] = self.cycles() - before
        elif op == "ticks":
            await self.ticks(step["count"])
        elif op == "set":
            getattr(self.dut, step["signal"]).value = step["value"]
        elif op == "observe":
            self.observed[step["name"]] = {name: await self.read(name) for name in step["signals"]}
        else:
            raise ValueError(f"unknown step {op}")

    def cycles(self):
        """Clock edges since time 0 (the testbench stands mid-cycle)."""
        return int(cocotb.utils.get_sim_time("ps")) // PERIOD_PS


@cocotb.test()
async def play(dut):
    p = params()
    rig = Rig(dut, p)
    wall = time.monotonic()
    dut.regs.value = p["regs"]
    dut.timing.value = p["timing"]
    dut.seed.value = p["seed"] or 0
    dut.reseed.value = int(p["seed"] is not None)
    for name in ("reload", "trigger_in", "flush"):
        getattr(dut, name).value = 0
    Clock(dut.clk, PERIOD_PS, unit="ps").start()
    await FallingEdge(dut.clk)

    async def script():
        for step in p["script"]:
            await rig.step(step)

    await with_timeout(script(), p["max_cycles"] * PERIOD_PS, "ps")
    dut.flush.value = 1
    await rig.ticks(2)
    dut.flush.value = 0
    await rig.ticks(1)
    Path(p["report"]).write_text(json.dumps({
        "observed": rig.observed, "cycles": rig.cycles(), "wall_s": time.monotonic() - wall}))
