"""The row source's ``row_ready`` against the bus's use of it, with a store that stalls at random:
the bus decides on even cycles from what is registered, and a row it starts on ``row_ready``
takes its ``R`` beats back to back from the next cycle (``row_started`` on the first; the next
decision may fall on its last beat). Every beat so taken must be there, in the order the store
sent it; and a row waits no longer than it must (``row_ready`` rises within two cycles of a
whole row being free)."""

import random

import pytest
from amaranth.sim import Simulator

from gateware.dlpc410.row_source import RowSource
from spec.facts import DMDS
from spec.schedule import row_cycles


@pytest.mark.parametrize("name,beats", [("test", 1), ("test", 2), ("test4", 1), ("dlp7000", 2)])
def test_a_row_started_on_row_ready_finds_every_beat(name, beats):
    dmd = DMDS[name]
    R = row_cycles(dmd, beats)
    width = dmd.bits_per_dclk * beats
    dut = RowSource(dmd, beats=beats, store_words=width // 64)
    rng = random.Random(R * 7 + beats)
    mask = (1 << width) - 1
    checked = {"beats": 0, "rows": 0, "waits": 0}

    async def bench(ctx):
        sent = taken = 0
        busy_until = -1            # the last cycle a started row takes a beat
        beat_cycles, first_beats = set(), set()
        free_since = None          # the cycle a whole row beyond the row under way was first buffered
        for t in range(6000):
            # the store: words at a rate that varies between a trickle and every cycle
            rate = 0.9 if (t // 500) % 2 else 0.25
            ctx.set(dut.words.valid, rng.random() < rate)
            ctx.set(dut.words.payload, (sent * 0x9E3779B97F4A7C15) & mask)
            # the bus: decide on even cycles once the row before has its last beat under way
            if t % 2 == 0 and t >= busy_until and ctx.get(dut.row_ready):
                beat_cycles.update(range(t + 1, t + R + 1))
                first_beats.add(t + 1)
                busy_until = t + R
                checked["rows"] += 1
                if free_since is not None:
                    assert t - free_since <= 2, (t, free_since)
                    checked["waits"] += 1
                free_since = None
            reading = t in beat_cycles
            ctx.set(dut.beats.ready, reading)
            ctx.set(dut.row_started, t in first_beats)
            if reading:
                assert ctx.get(dut.beats.valid), (t, taken)
                assert ctx.get(dut.beats.payload) == (taken * 0x9E3779B97F4A7C15) & mask, (t, taken)
                taken += 1
                checked["beats"] += 1
            if ctx.get(dut.words.valid) and ctx.get(dut.words.ready):
                sent += 1
            await ctx.tick()
            # a whole row free of the row under way (what row_ready should see; for the wait bound)
            owed = max(busy_until - t, 0)
            if free_since is None and sent - taken - owed >= R and t >= busy_until:
                free_since = t + 1

    sim = Simulator(dut)
    sim.add_clock(5e-9)
    sim.add_testbench(bench)
    sim.run()
    assert checked["rows"] > 100 and checked["beats"] > (checked["rows"] - 1) * R
    assert checked["waits"] > 20
