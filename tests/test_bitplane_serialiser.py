"""The bit-plane serialiser in the Amaranth simulator, against numpy."""

import random

import numpy as np
import pytest

from gateware.bitplane import Serialiser
from sim.harness.amaranth_sim import simulate, stream_collect, stream_feed
from sim.models import bitplane_model as bitplane
from sim.models import serialiser_stim
from spec.facts import TEST_DMD


def as_dict(payload):
    return {"data": payload.data, "plane": payload.plane, "word": payload.word,
            "row": payload.row, "block": payload.block, "frame": payload.frame}


def run(image, *, lanes, name, stall=0.0, idle=0.0, shuffle=False, frame=3):
    dmd = TEST_DMD
    dut = Serialiser(dmd, lanes=lanes)
    order = list(range(dmd.rows))
    if shuffle:
        random.Random(7).shuffle(order)
    beats = list(serialiser_stim.pixel_beats(image, lanes, frame=frame, row_order=order))
    n_words = bitplane.PLANES * dmd.rows * dmd.words_per_row
    out = {}

    async def feed(ctx):
        await stream_feed(ctx, dut.pixels, beats, idle=idle)

    async def drain_words(ctx):
        out["words"] = await stream_collect(ctx, dut.words, n_words, stall=stall, convert=as_dict)

    async def drain_rows(ctx):
        out["rows"] = await stream_collect(
            ctx, dut.rows, dmd.rows, stall=stall, rng=random.Random(5),
            convert=lambda p: {"planes": p.planes, "row": p.row, "block": p.block, "frame": p.frame})

    simulate(dut, [feed, drain_words, drain_rows], name=name, deadline=1e-2)
    assert all(w["frame"] == frame for w in out["words"])
    serialiser_stim.check(dmd, image, out["words"], out["rows"])
    return out


@pytest.mark.parametrize("kind", list(bitplane.extreme_images(TEST_DMD.rows, TEST_DMD.columns)))
def test_extreme_images(kind, test_name):
    image = bitplane.extreme_images(TEST_DMD.rows, TEST_DMD.columns)[kind]
    run(image, lanes=8, name=test_name)


@pytest.mark.parametrize("lanes", [1, 2, 8])
def test_random_image_with_backpressure(lanes, test_name):
    image = np.random.default_rng(lanes).integers(0, 256, (TEST_DMD.rows, TEST_DMD.columns), dtype=np.uint8)
    run(image, lanes=lanes, name=test_name, stall=0.4, idle=0.2, shuffle=True)


def test_full_throughput_8_lanes(test_name):
    """With 8 lanes and no stalls, one word leaves per cycle: ready never drops."""
    dmd = TEST_DMD
    dut = Serialiser(dmd, lanes=8)
    image = np.random.default_rng(9).integers(0, 256, (dmd.rows, dmd.columns), dtype=np.uint8)
    beats = list(serialiser_stim.pixel_beats(image, 8))
    cycles = {}

    async def feed(ctx):
        start = 0
        for i, beat in enumerate(beats):
            ctx.set(dut.pixels.payload, beat)
            ctx.set(dut.pixels.valid, 1)
            _, _, ready = await ctx.tick().sample(dut.pixels.ready)
            assert ready, f"serialiser stalled the input at beat {i}"
            start += 1
        ctx.set(dut.pixels.valid, 0)
        cycles["in"] = start

    async def drain(ctx):
        ctx.set(dut.words.ready, 1)
        ctx.set(dut.rows.ready, 1)
        n = 0
        while n < 8 * dmd.rows * dmd.words_per_row:
            _, _, valid = await ctx.tick().sample(dut.words.valid)
            n += valid

    simulate(dut, [feed, drain], name=test_name, deadline=1e-2)
    assert cycles["in"] == len(beats)


def test_pixels_per_cycle_figure():
    """The figure ``serialiser.pixels_per_cycle`` as the benchmark measures it, checked here
    against what 8 lanes must give (one 64-pixel run = 8 cycles in, 8 words out)."""
    from sim.bench.bitplane_figures import serialiser_throughput
    figure = serialiser_throughput(lanes=8, rows=4)
    # 4 rows of 1024 pixels = 512 input beats, plus the last run's 8 words draining after it
    assert figure["cycles"] == 512 + 8
