"""cocotb testbench of the bit-plane serialiser's generated Verilog (run by
``tests/test_bitplane_serialiser_verilog.py``)."""

import random

import cocotb
import numpy as np
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, with_timeout

from gateware.bitplane import row_flags_layout, word_layout
from gateware.protocol.layouts import pixel_layout
from sim.harness.cocotb_run import params
from sim.harness.cocotb_stream import StreamSink, StreamSource
from sim.models import bitplane_model as bitplane
from sim.models import serialiser_stim
from spec.facts import DMDS


async def reset(dut):
    cocotb.start_soon(Clock(dut.clk, 8, unit="ns").start())
    dut.rst.value = 1
    await ClockCycles(dut.clk, 3)
    dut.rst.value = 0


async def run_image(dut, image, *, stall, idle, seed):
    p = params()
    dmd, lanes = DMDS[p["dmd"]], p["lanes"]
    order = list(range(dmd.rows))
    random.Random(seed).shuffle(order)
    source = StreamSource(dut, "pixels", pixel_layout(dmd, lanes), dut.clk, idle=idle, seed=seed)
    words = StreamSink(dut, "words", word_layout(dmd), dut.clk, stall=stall, seed=seed + 1)
    rows = StreamSink(dut, "rows", row_flags_layout(dmd), dut.clk, stall=stall, seed=seed + 2)
    n_words = bitplane.PLANES * dmd.rows * dmd.words_per_row
    feeder = cocotb.start_soon(source.send(serialiser_stim.pixel_beats(image, lanes, row_order=order)))
    row_task = cocotb.start_soon(rows.receive(dmd.rows))
    got_words = await with_timeout(words.receive(n_words), 50, "ms")
    got_rows = await with_timeout(row_task, 1, "ms")
    await feeder
    serialiser_stim.check(dmd, image, got_words, got_rows)


@cocotb.test()
async def extreme_and_random_images(dut):
    """Every extreme image and a random one, under backpressure and idle input."""
    await reset(dut)
    dmd = DMDS[params()["dmd"]]
    for i, (name, image) in enumerate(bitplane.extreme_images(dmd.rows, dmd.columns, seed=3).items()):
        dut._log.info("image %s", name)
        await run_image(dut, image, stall=0.3, idle=0.1, seed=i)


@cocotb.test()
async def full_rate(dut):
    """No stalls: the words keep up with the pixels."""
    await reset(dut)
    dmd = DMDS[params()["dmd"]]
    image = np.random.default_rng(11).integers(0, 256, (dmd.rows, dmd.columns), dtype=np.uint8)
    await run_image(dut, image, stall=0.0, idle=0.0, seed=20)
