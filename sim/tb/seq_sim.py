"""Run the sequencer bench in the Amaranth simulator: a DLPC410 stand-in, triggers, a decoder.

The stand-in holds ECP2_FINISHED high, INIT_ACTIVE high for ``init_cycles`` and raises
RST_ACTIVE for ``rst_high`` cycles after each clocking pulse (``rst_high`` must not exceed the
``t_rst`` parameter less :data:`~gateware.dlpc410.schedule.RST_MARGIN`, as the plan
assumes). Everything else is recorded by a
:class:`sim.models.dlpc410_commands.CommandDecoder` in the sequencer's time base
(``status.now``; a command's cycle is its decision cycle, one before the pins show it).
"""

from dataclasses import dataclass, field

from gateware.dlpc410.facts import BlockMode
from gateware.dlpc410.params import Registers
from gateware.dlpc410.schedule import RST_MARGIN
from sim.harness.amaranth_sim import simulate
from sim.models.dlpc410_commands import CommandDecoder
from sim.tb.plane_source import SequencerBench

__all__ = ["Run", "run_bench"]


@dataclass
class Run:
    decoder: CommandDecoder
    status: dict = field(default_factory=dict)
    sync_out: list = field(default_factory=list)     # (now, level) at each change
    camera_out: list = field(default_factory=list)
    lights: list = field(default_factory=list)       # light taken at each sync_out fall
    releases: list = field(default_factory=list)     # (now, slot) handed back


def run_bench(dmd, params, frames, images=None, *, pins=(), soft=(), cycles, name, init_cycles=20,
              rst_high=None, early_pins=(), sync_pins=(), seed=None):
    """``pins``: ``now`` values at which the trigger pin rises (high for 4 cycles);
    ``early_pins``: testbench cycles (before initialisation ends) of extra rising edges."""
    dut = SequencerBench(dmd, frames, images)
    regs = Registers.const(params.registers(dmd))
    run = Run(CommandDecoder(dmd))
    rst_high = params.t_rst - RST_MARGIN if rst_high is None else rst_high
    pins, soft, sync_pins = set(pins), set(soft), set(sync_pins)

    async def bench(ctx):
        ctx.set(dut.regs, regs)
        ctx.set(dut.release.ready, 1)
        ctx.set(dut.pins.ecp2_finished, 1)
        ctx.set(dut.pins.init_active, 1)
        if seed is not None:
            ctx.set(dut.seed, seed)
            ctx.set(dut.reseed, 1)
            await ctx.tick()
            ctx.set(dut.reseed, 0)
        rst_left = 0
        high_left = 0
        sync_left = 0
        last_sync = last_cam = 0
        p = dut.pins
        sigs = (dut.status.now, p.dvalid, p.rowmd, p.rowad, p.blkmd, p.blkad, p.rst2blkz,
                p.din_a.rise, p.din_b.rise, p.din_a.fall, p.din_b.fall,
                dut.sync_out, dut.camera_out, dut.release.valid, dut.release.payload)
        for i in range(init_cycles):
            ctx.set(dut.trigger_in, i in early_pins)
            await ctx.tick()
        ctx.set(dut.trigger_in, 0)
        ctx.set(dut.pins.init_active, 0)
        running = False
        for _ in range(cycles):
            values = await ctx.tick().sample(*sigs)
            now, dv, rowmd, rowad, blkmd, blkad, r2, ar, br, af, bf, so, co, rv, rs = values[2:]
            if rv:
                run.releases.append((now, rs))
            running = running or now > 0
            if running:
                lanes = {("A", "rise"): ar, ("B", "rise"): br, ("A", "fall"): af, ("B", "fall"): bf}
                run.decoder.step(now - 1, dv, rowmd, rowad, blkmd, blkad, r2, lanes)
                if dv and blkmd in (BlockMode.RESET, BlockMode.MULTI) and run.decoder._beat == 1:
                    rst_left = rst_high
                if so != last_sync:
                    run.sync_out.append((now - 1, so))
                    if not so:
                        run.lights.append(run.decoder.take_light())
                    last_sync = so
                if co != last_cam:
                    run.camera_out.append((now, co))
                    last_cam = co
            # inputs for the next cycle, in the time base of the next cycle (now + 1)
            nxt = now + 1 if running else 0
            if nxt in pins:
                high_left = 4
            if nxt in sync_pins:
                sync_left = 4
            ctx.set(dut.trigger_in, high_left > 0)
            ctx.set(dut.sync_in, sync_left > 0)
            ctx.set(dut.soft_trigger, nxt in soft)
            high_left = max(0, high_left - 1)
            sync_left = max(0, sync_left - 1)
            ctx.set(dut.pins.rst_active, rst_left > 0)
            rst_left = max(0, rst_left - 1)
        st = ctx.get(dut.status)
        run.status = {k: int(getattr(st, k)) for k in
                      ("now", "frames", "triggers", "overruns", "early", "late", "underruns", "bad_frames")}

    simulate(dut, [bench], name=name, clocks={"sync": 200e6})
    return run
