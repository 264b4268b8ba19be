"""Bit-plane store throughput, measured in the Amaranth simulator against the MCB model.

``store.write_bytes_per_s``: pixel bytes per second into the memory with the serialiser (8 lanes)
and the store at ``sync`` = 125 MHz, pixels offered every cycle, from the first pixel to the last
word in memory, over whole DLP7000 rows. ``store.read_words_per_dmd_cycle``: the plane reader at
``dmd`` = 200 MHz reading one whole DLP7000 plane with the sequencer always ready;
``store.read_fraction_of_model_bandwidth``: that rate over the model's sustained bandwidth
(refresh taken off); ``store.xga_plane_read_us``: request to last word of that plane.
"""

import numpy as np

from gateware.store.reader import Reader
from sim.harness.amaranth_sim import simulate
from sim.models import bitplane, serialiser_stim
from sim.models.mcb import McbModel, McbTiming, amaranth_process
from sim.tb.store_chain import StoreChain
from spec.facts import DMDS

SYNC_HZ, DMD_HZ = 125e6, 200e6


def write_rate(rows=12, dmd="dlp7000"):
    geometry = DMDS[dmd]
    dut = StoreChain(geometry, lanes=8, slots=4)
    model = McbModel(4 * 2**20)
    image = np.random.default_rng(0).integers(0, 256, (rows, geometry.columns), dtype=np.uint8)
    beats = list(serialiser_stim.pixel_beats(image, 8, frame=1))
    n_words = bitplane.PLANES * rows * geometry.words_per_row
    result = {}

    async def feed(ctx):
        ctx.set(dut.bit_depth, 8)
        while not ctx.get(dut.mcb_write.calib_done):
            await ctx.tick()
        cycles = 0
        for beat in beats:
            ctx.set(dut.pixels.payload, beat)
            ctx.set(dut.pixels.valid, 1)
            while True:
                _, _, ready = await ctx.tick().sample(dut.pixels.ready)
                cycles += 1
                if ready:
                    break
        ctx.set(dut.pixels.valid, 0)
        while model.ports[0].words_written < n_words:
            await ctx.tick()
            cycles += 1
        result["elapsed"] = cycles

    simulate(dut, [feed], name="bench_store_write", clocks={"sync": SYNC_HZ, "dmd": DMD_HZ},
             processes=[amaranth_process(model.ports[0], dut.mcb_write, domain="sync", frequency=SYNC_HZ),
                        amaranth_process(model.ports[1], dut.mcb_read, domain="dmd", frequency=DMD_HZ)],
             waves=False, deadline=1e-3)
    pixels = rows * geometry.columns
    return {"bytes_per_s": pixels / (result["elapsed"] / SYNC_HZ), "cycles": result["elapsed"],
            "pixels": pixels}


def read_rate(dmd="dlp7000", timing=None):
    geometry = DMDS[dmd]
    dut = Reader(geometry, slots=4, domain="dmd")
    model = McbModel(4 * 2**20, ports=1, timing=timing)
    n_words = geometry.words_per_plane
    result = {}

    async def sequencer(ctx):
        cycles = 0
        while not ctx.get(dut.mcb.calib_done):
            await ctx.tick("dmd")
        ctx.set(dut.requests.payload, {"slot": 1, "plane": 5, "first_row": 0, "row_count": geometry.rows})
        ctx.set(dut.requests.valid, 1)
        ctx.set(dut.planes.ready, 1)
        words = 0
        while words < n_words:
            _, _, valid, ready = await ctx.tick("dmd").sample(dut.planes.valid, dut.requests.ready)
            if ready:
                ctx.set(dut.requests.valid, 0)
            cycles += 1
            words += valid
        result["cycles"] = cycles

    simulate(dut, [sequencer], name="bench_store_read", clocks={"dmd": DMD_HZ},
             processes=[amaranth_process(model.ports[0], dut.mcb, domain="dmd", frequency=DMD_HZ)],
             waves=False, deadline=1e-3)
    cycles = result["cycles"]
    rate = n_words / cycles
    sustained_words_per_cycle = model.timing.sustained_bytes_per_s / 8 / DMD_HZ
    return {"words_per_cycle": rate, "fraction": rate / sustained_words_per_cycle,
            "plane_us": cycles / DMD_HZ * 1e6, "cycles": cycles}


def run():
    w = write_rate()
    r = read_rate(timing=McbTiming())
    return {
        "store.write_bytes_per_s": (w["bytes_per_s"], "B/s"),
        "store.read_words_per_dmd_cycle": (r["words_per_cycle"], "word/cycle"),
        "store.read_fraction_of_model_bandwidth": (r["fraction"], "1"),
        "store.xga_plane_read_us": (r["plane_us"], "us"),
    }


if __name__ == "__main__":
    for name, (value, unit) in run().items():
        print(f"{name} = {value:.4g} {unit}")
