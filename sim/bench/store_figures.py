"""Bit-plane store throughput, measured in the Amaranth simulator against the MCB model.

``store.write_bytes_per_s``: pixel bytes per second into the memory with the serialiser (8 lanes)
and the store at ``sync`` = 125 MHz, pixels offered every cycle, from the first pixel to the last
word in memory, over whole DLP7000 rows.

``store.read_words_per_dmd_cycle_128``: the plane reader on its 128-bit port at ``dmd`` = 200 MHz
reading one whole DLP7000 plane alone, the sequencer always ready (64-bit words per cycle);
``store.read_fraction_of_model_bandwidth``: that rate over the model's sustained bandwidth
(refresh taken off); ``store.xga_plane_read_us``: request to last word of that plane.

``store.read_words_per_dmd_cycle_with_ingest``: the same reader over ``INGEST_PLANES`` DLP7000
planes back to back while the store's writer takes DLP7000 rows at the GigE line rate
(:data:`sim.rigs.fast_system_rig.INGEST_BYTES_PER_S`, 125 MB/s: a 64-bit word every 8 ``sync``
cycles) and writes them through its 64-bit port; ``store.dlp7000_row_period_cycles_with_ingest``:
the row period (even, ``dmd`` cycles) that rate sustains for 16-word rows, the one the system run's
plan uses (:func:`sim.rigs.fast_system_rig.read_rate`; a test holds the two together);
``store.ingest_bytes_per_s_during_read``: what the writer took meanwhile (the line rate if it kept
up).
"""

import math

import numpy as np
from amaranth import Module, Signal
from amaranth.lib import wiring

from gateware.store.reader import Reader
from gateware.store.writer import Writer
from sim.harness.amaranth_sim import simulate, stream_put
from sim.models import bitplane_model as bitplane
from sim.models import serialiser_stim
from sim.models.mcb_model import McbModel, McbTiming, amaranth_process, widths
from sim.rigs.fast_system_rig import INGEST_BYTES_PER_S
from sim.tb.store_chain import StoreChain
from spec.facts import DMDS
from spec.schedule import even

SYNC_HZ, DMD_HZ = 125e6, 200e6
#: Planes read back to back in the run with ingest (about 160 us, twenty refreshes).
INGEST_PLANES = 2


def write_rate(rows=12, dmd="dlp7000"):
    geometry = DMDS[dmd]
    dut = StoreChain(geometry, lanes=8, slots=4)
    model = McbModel(4 * 2**20, widths=widths(dut.mcb_write, dut.mcb_read))
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


class ReadUnderIngest(wiring.Component):
    """The store's reader (``dmd``) and writer (``sync``) side by side, each on its own MCB
    port, with counters the testbenches read: ``dmd_cycles`` and ``sync_cycles`` since reset,
    ``handed`` (reader transfers taken, the sequencer always ready), ``last_handed_at`` (the
    ``dmd`` cycle of the latest) and ``taken`` (words the writer took). Simulation only."""

    def __init__(self, dmd, *, slots=4, width=128):
        self.reader = Reader(dmd, slots=slots, width=width)
        self.writer = Writer(dmd, slots=slots)
        super().__init__({})
        self.dmd_cycles, self.sync_cycles = Signal(32), Signal(32)
        self.handed, self.last_handed_at, self.taken = Signal(32), Signal(32), Signal(32)

    def elaborate(self, platform):
        m = Module()
        m.submodules.reader = reader = self.reader
        m.submodules.writer = writer = self.writer
        m.d.comb += [reader.planes.ready.eq(1), writer.written.ready.eq(1)]
        m.d.dmd += self.dmd_cycles.eq(self.dmd_cycles + 1)
        m.d.sync += self.sync_cycles.eq(self.sync_cycles + 1)
        with m.If(reader.planes.valid):
            m.d.dmd += [self.handed.eq(self.handed + 1), self.last_handed_at.eq(self.dmd_cycles)]
        with m.If(writer.words.valid & writer.words.ready):
            m.d.sync += self.taken.eq(self.taken + 1)
        return m


def _row_words(dmd, row, slot=0):
    """A row as the serialiser gives it to the writer: the eight planes of each 64-pixel run in
    turn, ``last`` on the row's final word; the frame never completes."""
    wpr = dmd.words_per_row
    return [{"data": row * 1000 + w * 8 + plane, "slot": slot, "plane": plane, "row": row, "word": w,
             "last": w == wpr - 1 and plane == bitplane.PLANES - 1, "completes": 0}
            for w in range(wpr) for plane in range(bitplane.PLANES)]


def read_rate(dmd="dlp7000", timing=None, *, width=128, planes=1, ingest_bytes_per_s=0.0):
    """The reader's rate over ``planes`` whole planes read back to back (slot 1), in 64-bit words
    per ``dmd`` cycle, from the first request to the last word handed on; with
    ``ingest_bytes_per_s`` > 0 the writer meanwhile takes rows of slot 0 at that rate (a 64-bit
    word every ``8 * SYNC_HZ / rate`` cycles) and writes them."""
    geometry = DMDS[dmd]
    dut = ReadUnderIngest(geometry, width=width)
    model = McbModel(4 * 2**20, widths=widths(dut.writer.mcb, dut.reader.mcb), timing=timing)
    n_transfers = planes * geometry.words_per_plane * 64 // width
    result = {}

    async def sequencer(ctx):
        requests = dut.reader.requests
        while not ctx.get(dut.reader.mcb.calib_done):
            await ctx.tick("dmd")
        # the writer's first burst leaves once it holds two rows: from then on, writes are steady
        while ingest_bytes_per_s and not model.ports[0].words_written:
            await ctx.tick("dmd").repeat(16)
        result["start"], taken = ctx.get(dut.dmd_cycles), ctx.get(dut.taken)
        written = model.ports[0].words_written
        for plane in range(planes):
            ctx.set(requests.payload, {"slot": 1, "plane": plane, "first_row": 0, "row_count": geometry.rows})
            ctx.set(requests.valid, 1)
            await ctx.tick("dmd").until(requests.ready)
        ctx.set(requests.valid, 0)
        while ctx.get(dut.handed) < n_transfers:
            await ctx.tick("dmd").repeat(64)
        result["cycles"] = ctx.get(dut.last_handed_at) + 1 - result["start"]
        result["ingest_words"] = ctx.get(dut.taken) - taken
        result["written_words"] = model.ports[0].words_written - written
        result["done"] = True

    async def ingest(ctx):
        words = dut.writer.words
        period = 8 * SYNC_HZ / ingest_bytes_per_s
        row, offered = 0, 0
        while not ctx.get(dut.writer.mcb.calib_done):
            await ctx.tick()
        start = ctx.get(dut.sync_cycles)
        while "done" not in result:        # the row under way ends after the reads
            for word in _row_words(geometry, row):
                wait = start + math.ceil(offered * period) - ctx.get(dut.sync_cycles)
                if wait > 0:
                    await ctx.tick().repeat(wait)
                await stream_put(ctx, words, word)
                offered += 1
            row = (row + 1) % geometry.rows

    processes = [amaranth_process(model.ports[1], dut.reader.mcb, domain="dmd", frequency=DMD_HZ),
                 amaranth_process(model.ports[0], dut.writer.mcb, domain="sync", frequency=SYNC_HZ)]
    simulate(dut, [sequencer, *([ingest] if ingest_bytes_per_s else [])], name="bench_store_read",
             clocks={"sync": SYNC_HZ, "dmd": DMD_HZ}, processes=processes, waves=False, deadline=planes * 1e-3)
    cycles = result["cycles"]
    rate = n_transfers * width / 64 / cycles
    sustained_words_per_cycle = model.timing.sustained_bytes_per_s / 8 / DMD_HZ
    return {"words_per_cycle": rate, "fraction": rate / sustained_words_per_cycle,
            "plane_us": cycles / planes / DMD_HZ * 1e6, "cycles": cycles,
            "ingest_bytes_per_s": result["ingest_words"] * 8 / (cycles / DMD_HZ),
            "written_bytes_per_s": result["written_words"] * 8 / (cycles / DMD_HZ)}


def row_period(dmd, words_per_cycle):
    """The shortest even row period, in ``dmd`` cycles, that ``words_per_cycle`` keeps fed."""
    return even(math.ceil(dmd.words_per_row / words_per_cycle - 1e-9))


def run():
    w = write_rate()
    alone = read_rate(timing=McbTiming())
    busy = read_rate(timing=McbTiming(), planes=INGEST_PLANES, ingest_bytes_per_s=INGEST_BYTES_PER_S)
    reader = "gateware: the store's plane reader (128-bit port), Amaranth simulator, MCB model (sim.models.mcb_model)"
    alone_source = f"{reader}, one DLP7000 plane alone"
    busy_source = f"{reader}, {INGEST_PLANES} DLP7000 planes while the writer takes rows at the GigE line rate"
    return {
        "store.write_bytes_per_s": (w["bytes_per_s"], "B/s",
                                    "gateware: serialiser and store (StoreChain), Amaranth simulator, MCB model "
                                    "(sim.models.mcb_model), DLP7000 rows"),
        "store.read_words_per_dmd_cycle_128": (alone["words_per_cycle"], "word/cycle", alone_source),
        # (the name says it: a fraction of the memory model's sustained bandwidth)
        "store.read_fraction_of_model_bandwidth": (
            alone["fraction"], "1", "model: store.read_words_per_dmd_cycle_128 over the MCB model's sustained "
                                    "bandwidth, refresh taken off (sim.models.mcb_model.McbTiming)"),
        "store.xga_plane_read_us": (alone["plane_us"], "us", alone_source),
        "store.read_words_per_dmd_cycle_with_ingest": (busy["words_per_cycle"], "word/cycle", busy_source),
        "store.dlp7000_row_period_cycles_with_ingest": (
            row_period(DMDS["dlp7000"], busy["words_per_cycle"]), "cycle",
            "arithmetic: the shortest even row period that store.read_words_per_dmd_cycle_with_ingest keeps fed"),
        "store.ingest_bytes_per_s_during_read": (busy["ingest_bytes_per_s"], "B/s", busy_source),
    }


if __name__ == "__main__":
    for name, (value, unit, *_source) in run().items():
        print(f"{name} = {value:.4g} {unit}")
