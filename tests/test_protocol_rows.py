"""The row assembler (:class:`gateware.protocol.rows.RowAssembler`) against the protocol's row
rule as the reference model states it (:class:`sim.models.net_model.Rows`): records that split rows
anywhere, lost and reordered records, frames interleaved, a consumer that stalls."""

import random

import numpy as np

from gateware.protocol.layouts import position_bits
from gateware.protocol.rows import RowAssembler
from sim.harness.amaranth_sim import simulate
from sim.models.net_model import Rows
from sim.tb.endpoint_sim import assemble_rows, pixel_sink, plain
from spec import records
from spec.facts import TEST_DMD

DMD = TEST_DMD
PIXELS = DMD.rows * DMD.columns


def records_of(rng, frame, image, *, lose=0.0, swap=0.0):
    """A frame's pixels cut into records of random sizes (some shorter than a row, some
    spanning several); some lost, some swapped with the next."""
    out, offset = [], 0
    while offset < len(image):
        size = rng.choice([1, 7, DMD.columns - 3, DMD.columns, DMD.columns + 5, 3 * DMD.columns + 11, 700])
        size = min(size, len(image) - offset)
        if rng.random() >= lose:
            out.append((frame, offset, image[offset:offset + size]))
        offset += size
    for i in range(len(out) - 1):
        if rng.random() < swap:
            out[i], out[i + 1] = out[i + 1], out[i]
    return out


def run_assembler(pieces_records, *, stall, name, frame_bits=4):
    dut = RowAssembler(DMD, frame_bits=frame_bits)
    out = {"pixels": [], "cycles": 0}
    rng = random.Random(2)

    async def feed(ctx):
        for frame, offset, data in pieces_records:
            until = offset + len(data)
            for i, byte in enumerate(data):
                ctx.set(dut.pieces.payload, {"data": byte, "frame": frame, "position": offset + i,
                                             "until": until, "first": int(i == 0)})
                ctx.set(dut.pieces.valid, 1)
                await ctx.tick().until(dut.pieces.ready)
            ctx.set(dut.pieces.valid, 0)
            for _ in range(rng.randint(0, 3)):
                await ctx.tick()
        for _ in range(3 * DMD.columns):
            await ctx.tick()
        out["counters"] = plain(ctx.get(dut.counters), records.ROW_COUNTERS)

    drain = pixel_sink(dut, out["pixels"], stall=stall, seed=3)
    simulate(dut, [feed], processes=[drain], name=name, deadline=5e-3)
    return out


def test_rows_whole_and_in_order_whatever_the_records(seed, test_name):
    """Records cut at random (a fresh seed each run), some lost or swapped: every row leaves whole
    and in order, as the reference model says, and the rest are counted incomplete."""
    rng = random.Random(seed)
    images = [np.random.default_rng(f).integers(0, 256, PIXELS, dtype=np.uint8).tobytes() for f in range(4)]
    part = PIXELS // 2
    sent = (records_of(rng, 3, images[0][:part]) + records_of(rng, 4, images[1], lose=0.15)
            + records_of(rng, 5, images[2][:part], swap=0.2) + records_of(rng, 0xFFFF, images[3][:5 * DMD.columns])
            + records_of(rng, 6, images[0][:3 * DMD.columns]))
    model = Rows(DMD)
    want = [row for frame, offset, data in sent for row in model.record(frame, offset, data)]
    assert model.counters["rows_incomplete"] > 0 and len(want) > DMD.rows
    out = run_assembler(sent, stall=0.3, name=test_name)
    assert assemble_rows(out["pixels"], DMD.columns) == [(f & 15, r, d) for f, r, d in want]
    assert out["counters"] == model.counters
    # the newest frame in serial-number order: 6 follows 0xFFFF
    assert out["counters"]["newest_frame"] == 6


def test_a_split_row_waits_for_its_last_piece(test_name):
    """A row whose end has not come is held back: nothing of it leaves, and it is dropped when
    the next record does not continue it."""
    data = bytes(range(DMD.columns)) * 2
    half = DMD.columns // 2
    sent = [(1, 0, data[:DMD.columns + half]),       # row 0 whole, row 1 begun
            (1, 3 * DMD.columns, data[:DMD.columns])]  # row 3: row 1 abandoned
    out = run_assembler(sent, stall=0.0, name=test_name)
    assert [r for _f, r, _d in assemble_rows(out["pixels"], DMD.columns)] == [0, 3]
    assert out["counters"]["rows_incomplete"] == 1 and out["counters"]["rows"] == 2


def test_steady_stream_never_waits():
    """Records of one frame back to back, rows split: the assembler takes a pixel every cycle
    (the line's rate) while its consumer takes one every cycle."""
    dut = RowAssembler(DMD)
    image = bytes(PIXELS)
    size = 1462
    sent = [(1, o, image[o:o + size]) for o in range(0, PIXELS, size)]
    stalls = {"n": 0}

    async def feed(ctx):
        ctx.set(dut.pixels.ready, 1)
        for frame, offset, data in sent:
            for i, byte in enumerate(data):
                ctx.set(dut.pieces.payload, {"data": byte, "frame": frame, "position": offset + i,
                                             "until": offset + len(data), "first": int(i == 0)})
                ctx.set(dut.pieces.valid, 1)
                while not (await ctx.tick().sample(dut.pieces.ready))[2]:
                    stalls["n"] += 1
        ctx.set(dut.pieces.valid, 0)

    simulate(dut, [feed], name="rows_steady", waves=False, deadline=1e-3)
    assert stalls["n"] == 0
    assert position_bits(DMD) >= (PIXELS).bit_length()
