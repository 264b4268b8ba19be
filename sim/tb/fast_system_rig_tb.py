"""cocotb stimulus of the fast system run (:class:`sim.rigs.fast_system_rig.FastSystem`).

Python does not run per cycle here: the clocks are cocotb's C clocks, GMII comes from the replay
file, the memory and the DLPC410 responder are Verilog, the pins go to trace files. This
testbench only starts each replay, raises the trigger at chosen instants and waits on edges of
``replay_busy`` or on timers; the checks are made after the run on the traces
(:mod:`sim.rigs.xga_run`). Run by :func:`sim.rigs.xga_run.run` and :func:`~sim.rigs.xga_run.stream`
(``make sim``) and so by ``tests/test_system_xga.py``.

Sequence: a control record makes the store keep the frames as a sequence; the frames are sent;
``one_by_one`` frames are triggered, each once the one before has been shown and the next one
loaded, at a different phase of the trigger against the clock; then ``back_to_back`` triggers
come faster than frames can be shown (every ``fast_period_cycles``): each is held until the
sequencer is ready. Once the last frame has ended, a status query is sent and the reply is
recorded on the transmit pins.

With ``window`` (``{"after_us": ..}``), the first frame's last datagram (``held``) is sent in
the one-by-one phase: every signal is dumped from the moment it starts, through its last byte,
the frame's way through the store and its first row on the bus (``loading``), when the first
trigger comes (it is held until the frame is loaded), to ``after_us`` after sync out rises at the
frame's first pulse.
"""

import json
import shutil
import time
from pathlib import Path

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, FallingEdge, RisingEdge, Timer

from sim.harness.cocotb_run import params

SYNC_NS, DMD_NS = 8.0, 5.0


class Run:
    def __init__(self, dut, p):
        self.dut, self.p = dut, p
        self.wall0 = time.monotonic()
        self.events = {"sends": [], "triggers_ns": [], "trigger_edges_ns": [], "wall": {}}

    def now_ns(self):
        return cocotb.utils.get_sim_time("ns")

    def log(self, text):
        sim_us = self.now_ns() / 1e3
        self.dut._log.info("%s  [%.0f us simulated, %.0f s wall]", text, sim_us, time.monotonic() - self.wall0)

    async def start(self):
        dut = self.dut
        dut.trigger_in.value = 0
        dut.replay_start.value = 0
        dut.flush.value = 0
        # the edges of the two clocks never coincide (the GMII domains run on clk); the top
        # holds each domain in reset for its first cycles
        Clock(dut.clk, SYNC_NS, unit="ns").start()
        await Timer(750, "ps")
        Clock(dut.dmd_clk, DMD_NS, unit="ns").start()

    async def send(self, path, what, kind):
        """Play one replay file; returns when its last byte is on the pins."""
        dut = self.dut
        shutil.copyfile(path, self.p["replay"])
        await RisingEdge(dut.clk)
        t0, w0 = self.now_ns(), time.monotonic()
        dut.replay_start.value = 1
        await RisingEdge(dut.clk)
        dut.replay_start.value = 0
        await FallingEdge(dut.replay_busy)
        self.events["sends"].append({"what": what, "kind": kind, "start_ns": t0, "end_ns": self.now_ns(),
                                     "wall_start": w0 - self.wall0, "wall_end": time.monotonic() - self.wall0})
        self.log(f"{what} sent over GMII")

    async def trigger(self, phase_ps):
        """A trigger pulse, ``phase_ps`` after a ``dmd`` rising edge (the pin is asynchronous)."""
        dut = self.dut
        await RisingEdge(dut.dmd_clk)
        # the edge after this one samples the pin (phase_ps is under a cycle)
        self.events["trigger_edges_ns"].append(self.now_ns() + DMD_NS)
        if phase_ps:
            await Timer(phase_ps, "ps")
        self.events["triggers_ns"].append(self.now_ns())
        dut.trigger_in.value = 1
        await Timer(40, "ns")
        dut.trigger_in.value = 0

    def window_open(self):
        """Opens the wave window."""
        self.dut.wave_dump.value = 1
        self.events["window"] = {"open_ns": self.now_ns()}

    async def window_close(self, after_us):
        """Closes the wave window ``after_us`` after sync out rises (the frame's first pulse)."""
        await RisingEdge(self.dut.sync_out)
        await Timer(after_us, "us")
        self.dut.wave_dump.value = 0
        self.events["window"]["close_ns"] = self.now_ns()
        self.log("wave window closed")

    async def mark(self, at_ns, name):
        """Note the wall time when simulated time reaches ``at_ns``."""
        await Timer(round(at_ns - self.now_ns()), "ns")
        self.events["wall"][name] = time.monotonic() - self.wall0

    async def count_frames(self):
        """Counts the frames started: sync out rises at each frame's first pulse."""
        self.frames_started = 0
        while True:
            await RisingEdge(self.dut.sync_out)
            self.frames_started += 1

    async def progress(self, every_us):
        while True:
            await Timer(every_us, "us")
            self.log("running")

    async def frames_ended(self, count, give_up_ns):
        """Wait until ``count`` frames have started and the last has ended (sync out low), or
        until ``give_up_ns``; the checks after the run say what was missing."""
        while (self.frames_started < count or self.dut.sync_out.value) and self.now_ns() < give_up_ns:
            await Timer(10, "us")

    async def finish(self):
        """After the last frame: the status query (its reply goes to the transmit trace), the
        traces flushed, the memory model's rules checked, and the events written."""
        dut, p = self.dut, self.p
        await Timer(p["margin_us"], "us")
        self.check_memory()
        await self.send(p["status_query"], "status query", "query")
        await Timer(p["reply_us"], "us")
        dut.flush.value = 1
        await ClockCycles(dut.clk, 2)
        await ClockCycles(dut.dmd_clk, 2)
        dut.flush.value = 0
        self.check_memory()
        self.events["mcb_stalls"] = int(dut.mcb_stalls.value)
        self.events["sim_ns"] = self.now_ns()
        self.events["wall_s"] = time.monotonic() - self.wall0
        Path(p["report"]).write_text(json.dumps(self.events))

    def check_memory(self):
        fault = int(self.dut.mcb_fault.value)
        assert fault == 0, f"memory model: rule broken on a port (codes {fault:#04x}, see the log)"


@cocotb.test()
async def stream_frames(dut):
    p = params()
    run = Run(dut, p)
    await run.start()
    cocotb.start_soon(run.progress(p["progress_us"]))
    cocotb.start_soon(run.count_frames())
    period_ns = p["period_cycles"] * DMD_NS
    window = p.get("window")
    if window:
        dut.wave_dump.value = 0
    for send in p["sends"]:
        await run.send(send["path"], send["what"], send["kind"])
    await Timer(p["settle_us"], "us")
    shown = 0
    for index in range(p["one_by_one"]):
        if window and index == 0:
            # the first frame's last datagram: the frame (and the sequence) complete on its last byte
            run.window_open()
            cocotb.start_soon(run.window_close(window["after_us"]))
            held = p["held"]
            await run.send(held["path"], held["what"], held["kind"])
            # a trigger before the sequencer runs would be ignored: it runs once it loads rows
            await RisingEdge(dut.loading)
            run.log("the first frame's first row on the bus")
        # a different phase of the trigger against DCLK each time: latency has a spread
        await run.trigger((index * 1300) % int(DMD_NS * 1000))
        if window and index == 0:
            # held until the frame is loaded: wait for its first pulse before the next trigger
            await RisingEdge(dut.sync_out)
        elif index == 0:
            last_pulse = run.events["triggers_ns"][0] + p["last_pulse_cycles"] * DMD_NS
            cocotb.start_soon(run.mark(last_pulse, "first_frame_last_pulse"))
        await Timer(round(period_ns + p["margin_us"] * 1e3), "ns")
        shown += 1
        run.log(f"frame {shown} triggered and shown")
        run.check_memory()
    fast_ns = p["fast_period_cycles"] * DMD_NS
    for index in range(p["back_to_back"]):
        start = run.now_ns()
        await run.trigger((index * 700) % int(DMD_NS * 1000))
        shown += 1
        run.log(f"frame {shown} triggered, back to back")
        await Timer(round(start + fast_ns - run.now_ns()), "ns")
    # the held frames play one after another: the last ends its back-to-back lag after the loop
    # (sync out falls after its last group's final dark pulse); a memory that stalls may make it
    # later, so wait for it, two frames at most
    await run.frames_ended(p["one_by_one"] + p["back_to_back"],
                           run.now_ns() + p["back_to_back"] * (period_ns - fast_ns) + 2 * period_ns)
    await run.finish()


@cocotb.test()
async def stream_new_frames(dut):
    """A new frame at every trigger (:func:`sim.rigs.xga_run.stream`): the first frame sent and left
    to settle, then a trigger every ``trigger_period_cycles``; right after each trigger the next
    frame goes over GMII, while the one triggered is shown."""
    p = params()
    run = Run(dut, p)
    await run.start()
    cocotb.start_soon(run.progress(p["progress_us"]))
    cocotb.start_soon(run.count_frames())
    sends = p["sends"]
    await run.send(sends[0]["path"], sends[0]["what"], sends[0]["kind"])
    await Timer(p["settle_us"], "us")
    period_ns = p["trigger_period_cycles"] * DMD_NS
    first = run.now_ns()
    sending = None
    for index in range(len(sends)):
        wait = round(first + index * period_ns - run.now_ns())
        if wait > 0:
            await Timer(wait, "ns")
        if sending is not None:
            assert sending.done(), f"frame {index + 1} still on the wire at its trigger"
        await run.trigger((index * 700) % int(DMD_NS * 1000))
        run.log(f"frame {index + 1} triggered")
        if index + 1 < len(sends):
            following = sends[index + 1]
            sending = cocotb.start_soon(run.send(following["path"], following["what"], following["kind"]))
    await run.frames_ended(len(sends), run.now_ns() + 2 * period_ns)
    await run.finish()


@cocotb.test()
async def stream_chained_frames(dut):
    """Chained frames from the store while GigE writes (binary patterns,
    :func:`sim.rigs.xga_run.binary_stream`; gated frames, :func:`sim.rigs.gated_run.gated_stream`):
    the setup records (a bit depth, a register set of chained frames), the first frame, one
    trigger that starts the chain; then the other frames back to back over GMII, each written
    while the one before it repeats on the DMD; ``tail_us`` more after the last, then the
    status query."""
    p = params()
    run = Run(dut, p)
    await run.start()
    cocotb.start_soon(run.progress(p["progress_us"]))
    sends = p["sends"]
    for send in sends[:2]:
        await run.send(send["path"], send["what"], send["kind"])
    await Timer(p["settle_us"], "us")
    await run.trigger(0)
    run.log("the chain of patterns triggered")
    for send in sends[2:]:
        await run.send(send["path"], send["what"], send["kind"])
    await Timer(p["tail_us"], "us")
    await run.finish()
