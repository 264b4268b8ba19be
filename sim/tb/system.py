"""cocotb testbench of the projector's core (generated Verilog): frames in over GMII, a trigger,
the DLPC410 model on the pins, the camera's image compared with what was sent.

Clocks: ``sync``, ``gmii_rx``, ``gmii_tx`` at 125 MHz and ``dmd`` at 200 MHz, started at
fractions of a nanosecond from each other so that no two domains' edges coincide. The MCB model
serves both memory ports; the DLPC410 model drives the controller's outputs and checks every
rule; the frames are the host encoder's records inside scapy-built UDP datagrams.
"""

import json
import time
from pathlib import Path

import cocotb
import numpy as np
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, RisingEdge, Timer
from scapy.layers.inet import IP, UDP
from scapy.layers.l2 import Ether
from scapy.packet import Raw

from gateware.dlpc410 import schedule
from gateware.dlpc410.facts import DMDS
from gateware.dlpc410.params import PlaneOrder, Registers, ResetMode
from gateware.store.slots import SlotCounters
from host import records
from sim.harness.cocotb_run import params
from sim.harness.layout import pack, unpack
from sim.models import gmii
from sim.models.camera import Camera, to_lsb
from sim.models.dlpc410 import CocotbAdapter, Dlpc410
from sim.models.mcb import CocotbPort, McbModel
from sim.scene import default_scene

SYNC_NS, GMII_NS, DMD_NS = 8.0, 8.0, 5.0
HOST_MAC, HOST_IP = "02:00:00:00:00:99", "10.0.0.1"


def datagrams(p, payloads):
    return [bytes(Ether(src=HOST_MAC, dst=p["mac"]) / IP(src=HOST_IP, dst=p["ip"])
                  / UDP(sport=40000, dport=p["port"]) / Raw(payload)) for payload in payloads]


class System:
    def __init__(self, dut, p):
        self.dut, self.p = dut, p
        self.dmd = DMDS[p["dmd"]]
        self.memory = McbModel(p["memory_bytes"])
        self.plan = schedule.plan(self.dmd, 1e9 / DMD_NS, t_rst_s=p["t_rst"] * DMD_NS * 1e-9,
                                  t_settle_s=p["t_settle"] * DMD_NS * 1e-9, depth=8,
                                  reset_mode=ResetMode[p["mode"]], order=PlaneOrder[p["order"]])
        self.dlpc = Dlpc410(self.dmd, dclk=1e9 / DMD_NS, rst_active_cycles=p["t_rst"],
                            settle_cycles=p["t_settle"], init_cycles=p["init_cycles"],
                            init_grace_cycles=p["init_grace"], check_training=p.get("check_training", True))
        self.dmd_cycle = 0
        self.frames_sent = 0

    async def start(self):
        dut = self.dut
        dut.regs.value = pack(Registers, self.plan.params.registers(self.dmd))
        dut.gmii_rx.value = 0
        dut.trigger_in.value = 0
        dut.sync_in.value = 0
        dut.mdio_i.value = 1
        for rst in (dut.rst, dut.gmii_rx_rst, dut.gmii_tx_rst, dut.dmd_rst):
            rst.value = 1
        cocotb.start_soon(Clock(dut.clk, SYNC_NS, unit="ns").start())
        await Timer(250, "ps")
        cocotb.start_soon(Clock(dut.gmii_rx_clk, GMII_NS, unit="ns").start())
        await Timer(250, "ps")
        cocotb.start_soon(Clock(dut.gmii_tx_clk, GMII_NS, unit="ns").start())
        await Timer(250, "ps")
        cocotb.start_soon(Clock(dut.dmd_clk, DMD_NS, unit="ns").start())
        await ClockCycles(dut.clk, 4)
        for rst in (dut.rst, dut.gmii_rx_rst, dut.gmii_tx_rst, dut.dmd_rst):
            rst.value = 0
        cocotb.start_soon(CocotbPort(dut, "mcb_write", dut.clk, self.memory.ports[0], SYNC_NS).run())
        cocotb.start_soon(CocotbPort(dut, "mcb_read", dut.dmd_clk, self.memory.ports[1], DMD_NS).run())
        self.adapter = cocotb.start_soon(CocotbAdapter(self.dlpc, dut, dut.dmd_clk).run())
        cocotb.start_soon(self._count_dmd())

    async def _count_dmd(self):
        edge = RisingEdge(self.dut.dmd_clk)
        while True:
            await edge
            self.dmd_cycle += 1

    async def send(self, frames, errors=None):
        """Drive GMII with ``frames`` (no FCS; the stream adds preamble, FCS and gaps)."""
        edge = RisingEdge(self.dut.gmii_rx_clk)
        self.frames_sent += len(frames)
        for dv, er, byte in gmii.cycles(frames, errors=errors):
            await edge
            self.dut.gmii_rx.value = byte | (dv << 8) | (er << 9)
        await edge
        self.dut.gmii_rx.value = 0
        self.sent_at = self.dmd_cycle

    async def trigger(self):
        """A trigger edge on the pin; returns the dmd cycle it was raised on."""
        await RisingEdge(self.dut.dmd_clk)
        at = self.dmd_cycle
        self.dut.trigger_in.value = 1
        await ClockCycles(self.dut.dmd_clk, 8)
        self.dut.trigger_in.value = 0
        return at

    def pulses_after(self, cycle):
        return [c for c in self.dlpc.log if c.kind == "pulse" and c.cycle >= cycle]


@cocotb.test()
async def frame_over_gmii_is_shown_exactly(dut):
    p = params()
    system = System(dut, p)
    await system.start()
    dmd = system.dmd
    if p.get("scene"):
        images = default_scene(p["frames"], dmd.rows, dmd.columns)
    else:
        rng = np.random.default_rng(p["seed"])
        images = [rng.integers(0, 256, (dmd.rows, dmd.columns), dtype=np.uint8) for _ in range(p["frames"])]
        images[0][0, :] = np.arange(dmd.columns) % 256      # every grey level appears
    wall0 = time.monotonic()
    report = {"frames": [], "period_cycles": system.plan.frame_cycles, "rate_hz": system.plan.rate_hz,
              "lsb_cycles": system.plan.params.lsb}

    def encoded(index):
        payloads = records.image_records(images[index], frame=index)
        bad = datagrams({**p, "port": p["port"] + 1}, payloads[:1])   # wrong port: dropped, counted
        return datagrams(p, payloads) + bad

    # Streaming, as a renderer does it: each frame is sent while the one before it is shown, so
    # it is complete when the sequencer reaches the end of that frame and takes the next one.
    await system.send(encoded(0))
    await ClockCycles(dut.dmd_clk, p["settle_after_send"])
    period = system.plan.frame_cycles
    for index, image in enumerate(images):
        pin = await system.trigger()
        sending = cocotb.start_soon(system.send(encoded(index + 1))) if index + 1 < len(images) else None
        await ClockCycles(dut.dmd_clk, period + p["t_rst"] * 4)
        pulses = system.pulses_after(pin)
        assert pulses, "the trigger produced no clocking pulse"
        first = pulses[0].cycle
        light = Camera(system.dlpc, ramp_cycles=0).image(first, first + period)
        error = np.abs(to_lsb(light, system.plan.params.lsb) - image.astype(np.float64))
        report["frames"].append({"latency_cycles": first - pin, "max_error_lsb": float(error.max())})
        dut._log.info("frame %d: trigger to first pulse %d cycles, max error %.3g LSB",
                      index, first - pin, error.max())
        matches = [j for j, other in enumerate(images)
                   if np.abs(to_lsb(light, system.plan.params.lsb) - other).max() < 1e-9]
        if error.max() >= 1e-9:     # what the store made of the rows, to say why
            dut._log.info("store counters %s", unpack(SlotCounters, int(dut.store.counters.value)))
        assert error.max() < 1e-9, (f"frame {index}: {int((error > 1e-9).sum())} pixels wrong; the image shown "
                                    f"equals sent frame(s) {matches}; period {period}, send ended at dmd cycle "
                                    f"{system.sent_at}, pulses {[(c.cycle, c.kind) for c in pulses[:3]]}")
        if sending is not None:
            await sending
            await ClockCycles(dut.dmd_clk, p["settle_after_send"])
    report["wall_s"] = time.monotonic() - wall0
    report["dmd_cycles"] = system.dmd_cycle
    report["gmii_frames_sent"] = system.frames_sent
    report["dlpc410_commands"] = len(system.dlpc.log)
    Path(p["report"]).write_text(json.dumps(report))
