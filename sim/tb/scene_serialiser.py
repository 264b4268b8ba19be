"""cocotb: stream the default scene through the serialiser's Verilog, check every plane, time it."""

import json
import time
from pathlib import Path

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, RisingEdge

from gateware.bitplane import pixel_layout, row_flags_layout, word_layout
from gateware.dlpc410.facts import DMDS
from sim.harness.cocotb_run import params
from sim.harness.cocotb_stream import StreamSink, StreamSource
from sim.models import bitplane, serialiser_stim
from sim.scene import default_scene


@cocotb.test()
async def scene(dut):
    p = params()
    dmd, lanes = DMDS[p["dmd"]], p["lanes"]
    cocotb.start_soon(Clock(dut.clk, 8, unit="ns").start())
    dut.rst.value = 1
    await ClockCycles(dut.clk, 3)
    dut.rst.value = 0
    source = StreamSource(dut, "pixels", pixel_layout(dmd, lanes), dut.clk)
    words = StreamSink(dut, "words", word_layout(dmd), dut.clk)
    rows = StreamSink(dut, "rows", row_flags_layout(dmd), dut.clk)
    n_words = bitplane.PLANES * dmd.rows * dmd.words_per_row
    report = {"frames": []}
    wall0 = time.monotonic()
    for index, image in enumerate(default_scene(p["frames"], dmd.rows, dmd.columns)):
        cycles = 0

        async def count():
            nonlocal cycles
            while True:
                await RisingEdge(dut.clk)
                cycles += 1
        counter = cocotb.start_soon(count())
        t0 = time.monotonic()
        feeder = cocotb.start_soon(source.send(serialiser_stim.pixel_beats(image, lanes, frame=index % 16)))
        row_task = cocotb.start_soon(rows.receive(dmd.rows))
        got = await words.receive(n_words)
        got_rows = await row_task
        await feeder
        counter.cancel()
        serialiser_stim.check(dmd, image, got, got_rows)
        wall = time.monotonic() - t0
        pixels = dmd.rows * dmd.columns
        dut._log.info("frame %d of %d: %d pixels in %d cycles (%.2f pixel/cycle), all 8 planes equal "
                      "numpy's, %.1f s wall", index + 1, p["frames"], pixels, cycles, pixels / cycles, wall)
        report["frames"].append({"cycles": cycles, "pixels": pixels, "wall_s": wall})
    report["wall_s"] = time.monotonic() - wall0
    Path(p["report"]).write_text(json.dumps(report))
