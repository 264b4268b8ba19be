"""Run the sequencer bench in the Amaranth simulator under the rule-checking DLPC410 model.

:class:`sim.models.dlpc410_model.Dlpc410` plays the controller (:func:`dlpc410_for`): it drives
ECP2_FINISHED, INIT_ACTIVE (checking the training pattern meanwhile) and RST_ACTIVE, decodes every
row cycle, keeps the DMD's memory and mirrors, and raises
:class:`~sim.models.dlpc410_model.RuleBreak` on the first broken rule. Its RST_ACTIVE time and
settle time are the plan's ``t_rst_s`` and ``t_settle_s`` (the facts, or the scaled-down values of a
test), so the sequencer's parameters are checked against the times they were planned for.

The model's command log, moved to the sequencer's time base (``status.now``; a command's cycle
is its decision cycle, :data:`~spec.schedule.DECISION_TO_PINS` before the pins show it), is what
the tests compare with the schedule model; the model's mirror history feeds the camera model
(:func:`frame_lights`).
"""

from dataclasses import dataclass, field

from amaranth.lib import data

from gateware.dlpc410.layouts import Status
from gateware.registers import Registers
from sim.harness.amaranth_sim import simulate
from sim.models.camera_model import Camera
from sim.models.dlpc410_model import Dlpc410, amaranth_process
from sim.tb.plane_source import SequencerBench
from spec.schedule import DECISION_TO_PINS, FABRIC_HZ, RST_MARGIN

__all__ = ["Run", "run_bench", "dlpc410_for", "frame_lights", "period_light", "INIT_CYCLES", "INIT_GRACE",
           "CAMERA_RAMP", "CAMERA_DELAY"]

#: INIT_ACTIVE high this long after ARSTZ rises (the 220 ms of the facts, shortened).
INIT_CYCLES = 20
#: The training pattern runs on while the sequencer's two-flip-flop synchroniser sees
#: INIT_ACTIVE fall, and the cycle its ``running`` flag needs.
INIT_GRACE = 4
#: Camera mirror transition on the scaled-down test timing (the facts' 4 us crossover scaled as
#: RST_ACTIVE is in the tests), and the delay from the pulse to the start of the motion.
CAMERA_RAMP = 16
CAMERA_DELAY = 4


@dataclass
class Run:
    model: Dlpc410
    shift: int = 0                                   # sequencer time base = model cycle + shift
    commands: list = field(default_factory=list)     # the model's log in the sequencer's time base
    status: dict = field(default_factory=dict)
    sync_out: list = field(default_factory=list)     # (now, level) at each change
    camera_out: list = field(default_factory=list)
    ready: list = field(default_factory=list)        # (now, level) at each change (the rig's trace)
    gate_out: list = field(default_factory=list)     # (now, level) at each change (the rig's trace)
    releases: list = field(default_factory=list)     # (now, slot) handed back
    lights: list = field(default_factory=list)       # camera images of the frames (frame_lights)
    report: dict = field(default_factory=dict)       # on the rig: the testbench's (sim.rigs.seq_rig)

    def frames(self):
        """``(first, last)`` model cycles of each shown frame: sync out rising and falling."""
        rises = [t + 1 - self.shift for t, level in self.sync_out if level]
        falls = [t + 1 - self.shift for t, level in self.sync_out if not level]
        return list(zip(rises, falls, strict=False))


def dlpc410_for(dmd, p, *, init_cycles=INIT_CYCLES, ecp2_cycles=4):
    """The rule model with the RST_ACTIVE and settle times ``p`` (schedule Params) was planned
    for (``t_rst`` covers RST_ACTIVE plus :data:`~spec.schedule.RST_MARGIN`), at its beats, and
    under the settle reading it was planned for (the paper's when ``p.t_flip``)."""
    paper = p.t_flip > 0
    return Dlpc410(dmd, beats=p.beats, clock_hz=FABRIC_HZ, rst_active_cycles=p.t_rst - RST_MARGIN,
                   settle_cycles=p.t_flip if paper else p.t_settle, reading="paper" if paper else "ti",
                   init_cycles=init_cycles, init_grace_cycles=INIT_GRACE,
                   ecp2_cycles=ecp2_cycles, strict_rst_active=p.strict_rst)


def frame_lights(model, frames, *, ramp=CAMERA_RAMP, delay=CAMERA_DELAY):
    """The camera's image of each frame (light in cycles, every column); ``frames``: ``(first,
    last)`` model cycles of its first and last pulse. The window holds the frame: from its
    first pulse to the end of the last pulse's mirror motion."""
    camera = Camera(model, ramp_cycles=ramp, delay_cycles=delay, visible=False)
    return [camera.image(first, last + delay + ramp) for first, last in frames]


def period_light(model, first, end, *, ramp=CAMERA_RAMP, delay=CAMERA_DELAY):
    """The camera's image over ``[first, end)`` model cycles (light in cycles, every column): one
    period of chained phased frames, which overlap (a group starts the next while another ends
    this one), so no window holds one frame alone; over a period every group shows the whole of
    its frame."""
    return Camera(model, ramp_cycles=ramp, delay_cycles=delay, visible=False).image(first, end)


def run_bench(dmd, params, frames, images=None, *, pins=(), soft=(), cycles, name,
              early_pins=(), sync_pins=(), seed=None, model=None):
    """Run until the sequencer's time base reaches ``cycles``.

    ``pins``: ``now`` values at which the trigger pin rises (high for 4 cycles); ``early_pins``:
    testbench cycles (before initialisation ends) of extra rising edges. ``model``: the
    controller (default :func:`dlpc410_for`)."""
    dut = SequencerBench(dmd, frames, images, beats=params.beats)
    regs = Registers.const(params.registers(dmd))
    model = dlpc410_for(dmd, params) if model is None else model
    run = Run(model)
    pins, soft, sync_pins = set(pins), set(soft), set(sync_pins)

    async def bench(ctx):
        ctx.set(dut.regs, regs)
        ctx.set(dut.release.ready, 1)
        tick = 0                      # the model's cycle of the sampled values
        if seed is not None:
            ctx.set(dut.seed, seed)
            ctx.set(dut.reseed, 1)
            await ctx.tick()
            tick += 1
            ctx.set(dut.reseed, 0)
        high_left = sync_left = 0
        last_sync = last_cam = 0
        sigs = (dut.status.now, dut.sync_out, dut.camera_out, dut.release.valid, dut.release.payload)
        now = 0
        while now < cycles:
            now, so, co, rv, rs = (await ctx.tick().sample(*sigs))[2:]
            running = now > 0
            if running:
                run.shift = now - tick
                if rv:
                    run.releases.append((now, rs))
                if so != last_sync:
                    run.sync_out.append((now - 1, so))
                    last_sync = so
                if co != last_cam:
                    run.camera_out.append((now, co))
                    last_cam = co
            tick += 1
            # inputs for the next cycle, in the time base of the next cycle (now + 1)
            nxt = now + 1 if running else None
            if nxt in pins:
                high_left = 4
            if nxt in sync_pins:
                sync_left = 4
            ctx.set(dut.trigger_in, high_left > 0 or (not running and tick in early_pins))
            ctx.set(dut.sync_in, sync_left > 0)
            ctx.set(dut.soft_trigger, nxt in soft)
            high_left = max(0, high_left - 1)
            sync_left = max(0, sync_left - 1)
        st = ctx.get(dut.status)
        run.status = {name: int(getattr(st, name)) for name, _ in data.Layout.cast(Status)}

    process = amaranth_process(model, dut.pins)
    simulate(dut, [bench], name=name, clocks={"sync": 200e6}, processes=[process])
    run.commands = model.commands(run.shift - DECISION_TO_PINS)
    return run
