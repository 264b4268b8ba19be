"""Running the endpoint (:class:`gateware.protocol.endpoint.Endpoint`) in the Amaranth simulator.

Frames go in as MAC byte beats with chosen gaps; everything that comes out is collected: image
rows, transmitted frames, trigger pulses, sequencer register sets, the counters and the configuration at the end. Shared
by the unit tests and the benchmark.
"""

import random

from gateware.protocol.endpoint import Endpoint
from sim.harness.amaranth_sim import simulate
from sim.models.frames import Addresses, byte_beats
from spec import records
from spec.facts import TEST_DMD

__all__ = ["run", "plain", "assemble_rows", "pixel_sink"]


def plain(const, table):
    """A struct value read from the simulator -> ``{name: int}``."""
    return {name: int(const[name]) for name, _ in table}


def assemble_rows(pixels, columns):
    """Pixel transfers ``(frame, row, column, value)`` -> ``[(frame, row, bytes)]`` in order,
    checking that each row came whole and left to right."""
    rows, current = [], None
    for frame, row, column, value in pixels:
        if column == 0:
            assert current is None or len(current[2]) == columns, "a row was cut short"
            current = (frame, row, bytearray())
            rows.append(current)
        assert current is not None and (current[0], current[1]) == (frame, row) \
            and column == len(current[2]), f"pixel out of order at frame {frame} row {row} column {column}"
        current[2].append(value)
    assert current is None or len(current[2]) == columns, "the last row was cut short"
    return [(f, r, bytes(b)) for f, r, b in rows]


def pixel_sink(dut, taken, *, stall=0.0, seed=0, took=None):
    """A process that takes ``dut.pixels``, not ready on a ``stall`` fraction of cycles, and
    appends each pixel taken to ``taken`` as ``(frame, row, column, value)`` (then calls
    ``took(payload)``, if given)."""
    async def sink(ctx):
        prng = random.Random(seed)
        while True:
            ready = not (stall and prng.random() < stall)
            ctx.set(dut.pixels.ready, ready)
            _, _, valid, p = await ctx.tick().sample(dut.pixels.valid, dut.pixels.payload)
            if valid and ready:
                taken.append((p.frame, p.row, p.column, p.pixels[0]))
                if took is not None:
                    took(p)
    return sink


def run(frames, *, name, dmd=TEST_DMD, addresses=None, gap=(12, 12), seed=0, pixel_stall=0.0,
        tx_stall=0.0, status=None, buffer_depth=16384, waves=None, settle=400, settle_each=None):
    """Feed ``frames`` (a list of ``(bytes, bad)``) with ``gap`` idle cycles (uniform in the
    range) between frames. Returns a dict of what came out.

    With ``settle_each``, wait after each frame until nothing has come out for that many cycles
    and record a snapshot (counters, pixels and frames sent so far) in ``snapshots``: the
    effects of each frame, one by one."""
    a = addresses or Addresses()
    dut = Endpoint(dmd, mac=a.mac, ip=a.ip, port=a.port, buffer_depth=buffer_depth)
    rng = random.Random(seed)
    out = {"pixels": [], "tx": [], "triggers": 0, "registers": [], "entries": [], "sequence_starts": 0, "cycle": 0,
           "activity": 0, "last_in": [],
           "first_pixel": [], "snapshots": [], "rx_stalls": 0}

    async def clock(ctx):
        async for _ in ctx.tick():
            out["cycle"] += 1

    async def feed(ctx):
        if status is not None:
            ctx.set(dut.status, status)
        for raw, bad in frames:
            for _ in range(rng.randint(*gap)):
                await ctx.tick()
            for beat in byte_beats(raw, bad):
                ctx.set(dut.rx.payload, beat)
                ctx.set(dut.rx.valid, 1)
                while not (await ctx.tick().sample(dut.rx.ready))[2]:
                    out["rx_stalls"] += 1
            out["last_in"].append(out["cycle"])
            ctx.set(dut.rx.valid, 0)
            if settle_each:
                await quiet(ctx, settle_each)
                out["snapshots"].append(snapshot(ctx))
        await quiet(ctx, settle)
        out.update(snapshot(ctx))

    async def quiet(ctx, cycles):
        while out["cycle"] - max(out["activity"], out["last_in"][-1] if out["last_in"] else 0) < cycles:
            await ctx.tick()

    def snapshot(ctx):
        return {"net": plain(ctx.get(dut.net_counters), records.NET_COUNTERS),
                "app": plain(ctx.get(dut.app_counters), records.APP_COUNTERS),
                "config": plain(ctx.get(dut.settings), records.CONFIG),
                "pixel_count": len(out["pixels"]), "tx_count": len(out["tx"]),
                "triggers": out["triggers"], "register_count": len(out["registers"]),
                "entry_count": len(out["entries"])}

    def took(p):
        out["activity"] = out["cycle"]
        if p.column == 0:
            out["first_pixel"].append(out["cycle"])

    pixels = pixel_sink(dut, out["pixels"], stall=pixel_stall, seed=seed + 1, took=took)

    async def tx(ctx):
        trng = random.Random(seed + 2)
        current = bytearray()
        while True:
            ready = not (tx_stall and trng.random() < tx_stall)
            ctx.set(dut.tx.ready, ready)
            ctx.set(dut.registers.ready, 1)
            ctx.set(dut.entries.ready, 1)
            _, _, valid, beat, trigger, regs_valid, regs, entry_valid, entry, start = await ctx.tick().sample(
                dut.tx.valid, dut.tx.payload, dut.trigger, dut.registers.valid, dut.registers.payload,
                dut.entries.valid, dut.entries.payload, dut.sequence_start)
            out["triggers"] += trigger
            out["sequence_starts"] += start
            if regs_valid:
                out["registers"].append(regs.as_value().value)
            if entry_valid:
                out["entries"].append({name: int(getattr(entry, name)) for name, _ in records.ENTRY})
            if valid and ready:
                current.append(beat.data)
                out["activity"] = out["cycle"]
                if beat.last:
                    out["tx"].append(bytes(current))
                    current = bytearray()

    simulate(dut, [feed], processes=[clock, pixels, tx], name=name, waves=waves, deadline=1.0)
    out["rows"] = assemble_rows(out["pixels"], dmd.columns)
    return out
