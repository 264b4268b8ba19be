"""Serialiser throughput, measured in the Amaranth simulator with a consumer that never stalls."""

import numpy as np

from gateware.bitplane import Serialiser
from sim.harness.amaranth_sim import simulate
from sim.models import bitplane_model as bitplane
from sim.models import serialiser_stim
from spec.facts import DMDS


def serialiser_throughput(lanes=8, rows=8, dmd="dlp7000"):
    """Pixels per cycle over ``rows`` full rows: cycles from the first pixel offered to the last
    word taken, with valid held high and ready always high."""
    geometry = DMDS[dmd]
    dut = Serialiser(geometry, lanes=lanes)
    image = np.random.default_rng(0).integers(0, 256, (rows, geometry.columns), dtype=np.uint8)
    beats = list(serialiser_stim.pixel_beats(image, lanes))
    n_words = bitplane.PLANES * rows * geometry.words_per_row
    result = {}

    async def feed(ctx):
        for beat in beats:
            ctx.set(dut.pixels.payload, beat)
            ctx.set(dut.pixels.valid, 1)
            await ctx.tick().until(dut.pixels.ready)
        ctx.set(dut.pixels.valid, 0)

    async def drain(ctx):
        ctx.set(dut.words.ready, 1)
        ctx.set(dut.rows.ready, 1)
        cycles = words = 0
        while words < n_words:
            _, _, valid = await ctx.tick().sample(dut.words.valid)
            cycles += 1
            words += valid
        result["cycles"] = cycles

    simulate(dut, [feed, drain], name=f"bench_serialiser_{lanes}", waves=False, deadline=1e-2)
    pixels = rows * geometry.columns
    return {"pixels_per_cycle": pixels / result["cycles"], "cycles": result["cycles"], "pixels": pixels}


def run():
    t = serialiser_throughput()
    return {
        "serialiser.pixels_per_cycle": (t["pixels_per_cycle"], "pixel/cycle",
                                        "gateware: serialiser (8 lanes), Amaranth simulator, 8 DLP7000 rows, "
                                        "consumer never stalling"),
        "serialiser.pixels_per_s_at_125mhz": (t["pixels_per_cycle"] * 125e6, "pixel/s",
                                              "arithmetic: serialiser.pixels_per_cycle x 125 MHz"),
    }
