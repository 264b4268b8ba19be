"""cocotb testbench: the projector's core as a virtual projector on a TAP interface.

The core (generated Verilog, small geometry, as :mod:`sim.tb.system_tb` runs it: the MCB model on
both memory ports, the rule-checking DLPC410 model on its pins) is attached to a TAP device of
the network namespace it runs in (:mod:`sim.rigs.virtual_run` makes both): every Ethernet frame the
operating system sends on the TAP goes into the GMII receive pins (padded to 60 bytes and given
its FCS, as a network card would), and every frame on the transmit pins whose FCS is right goes
back to the TAP. So the namespace's own stack, and any program in it, ARPs, pings and talks UDP to
the projector.

Power-up: before the TAP is opened the testbench configures the core over GMII as a bench unit
would be: the small geometry's scaled RST_ACTIVE and settle times, software triggers
(``python -m host trigger``), bit depth 8, armed. These two records count in the status reply.

What the DMD shows: at the end of every frame (``sync_out`` falling) the camera model integrates
the mirrors from the frame's first clocking pulse, and the frame is written as an 8-bit PNG
(``frameNNNN.png``: the light over the least significant plane's time, shifted to 8 bits for the
frame's bit depth; both are those of the newest sequencer and control records seen on the wire).
The testbench ends when the wall-clock time ``seconds`` has passed or the file ``stop`` exists,
and writes a report.

Run by :mod:`sim.rigs.virtual_run` (``make sim VIRTUAL=...``) and so by
``tests/test_virtual_projector.py``.
"""

import fcntl
import json
import os
import struct
import time
from pathlib import Path

import cocotb
import numpy as np
from cocotb.triggers import ClockCycles, FallingEdge, RisingEdge

from host import codec
from sim.models.camera_model import Camera, to_lsb
from sim.rigs.system_run import plan as run_plan
from spec.registers import TriggerMode

from .system_tb import System

#: ``linux/if_tun.h``
TUNSETIFF, IFF_TAP, IFF_NO_PI = 0x400454CA, 0x0002, 0x1000
#: Simulated cycles of the system clock between two looks at the TAP when it is quiet (2 us).
POLL_CYCLES = 250
#: Frames taken from the TAP at a time.
BATCH = 32


def open_tap(name):
    """The TAP device ``name`` (it exists, in this process's namespace), non-blocking, frames
    without the packet-information header."""
    fd = os.open("/dev/net/tun", os.O_RDWR | os.O_NONBLOCK)
    fcntl.ioctl(fd, TUNSETIFF, struct.pack("16sH", name.encode(), IFF_TAP | IFF_NO_PI))
    return fd


def waiting(fd):
    frames = []
    while len(frames) < BATCH:
        try:
            frames.append(os.read(fd, 65536))
        except BlockingIOError:
            break
    return frames


class Camera8:
    """Writes each frame the DMD showed as a PNG."""

    def __init__(self, system, out):
        self.system, self.out, self.shown = system, Path(out), []

    def settings(self):
        """(lsb, bit depth) of the newest sequencer and control records the projector took."""
        net = self.system.net
        return net.registers[-1]["lsb"], net.config["bit_depth"]

    async def run(self):
        from PIL import Image
        system, dut = self.system, self.system.dut
        while True:
            await RisingEdge(dut.sync_out)
            start = system.dmd_cycle
            await FallingEdge(dut.sync_out)
            await system.dmd_clock.cycles(4)
            end = system.dmd_cycle
            pulses = [c for c in system.pulses_after(start - 4) if c.cycle <= end]
            if not pulses:
                continue
            lsb, depth = self.settings()
            level = to_lsb(Camera(system.dlpc, ramp_cycles=0).image(pulses[0].cycle, end), lsb)
            whole = np.rint(level)
            grey = np.clip(whole.astype(np.int64) << (8 - depth), 0, 255).astype(np.uint8)
            path = self.out / f"frame{len(self.shown):04d}.png"
            Image.fromarray(grey, "L").save(path)
            self.shown.append({"png": str(path), "first_pulse": pulses[0].cycle, "lsb": lsb, "depth": depth,
                               "whole_levels": bool(np.abs(level - whole).max() < 1e-9)})
            dut._log.info("frame shown: %s (%d-bit)", path.name, depth)


@cocotb.test()
async def virtual_projector(dut):
    system = await System.started(dut)
    p, dmd = system.p, system.dmd
    registers = {**run_plan(p).params.registers(dmd), "trigger": TriggerMode.SOFTWARE}
    await system.records([codec.sequencer_record(registers, system.next_sequence(), dmd=dmd),
                          codec.control_record(system.next_sequence(), bit_depth=8, armed=1)])
    camera = Camera8(system, p["out"])
    cocotb.start_soon(camera.run())

    report = await bridge(dut, system, p)
    Path(p["report"]).write_text(json.dumps({**report, "shown": camera.shown, "dmd_cycles": system.dmd_cycle}))


async def bridge(dut, host, p):
    """Carry frames between the TAP ``p["tap"]`` and ``host`` (a started
    :class:`~sim.tb.gmii_host.GmiiHost` on ``dut``'s GMII pins) until ``p["seconds"]`` of wall
    time have passed or the file ``p["stop"]`` exists; writes ``p["ready"]`` once the TAP is open.
    Returns the frames each way and what stopped it."""
    fd = open_tap(p["tap"])
    forwarded, received = len(host.tx_frames), 0
    stop, deadline = Path(p["stop"]), time.monotonic() + p["seconds"]
    Path(p["ready"]).write_text(json.dumps({"ip": p["ip"], "mac": p["mac"], "port": p["port"]}))
    dut._log.info("up on %s", p["tap"])
    try:
        while time.monotonic() < deadline and not stop.exists():
            frames = waiting(fd)
            if frames:
                received += len(frames)
                await host.send(frames)
            else:
                await ClockCycles(dut.clk, POLL_CYCLES)
            for frame in host.tx_frames[forwarded:]:
                os.write(fd, frame)
            forwarded = len(host.tx_frames)
    finally:
        os.close(fd)
    return {"frames_received": received, "frames_sent": forwarded, "stopped": "file" if stop.exists() else "time"}
