"""Queues: the synchronous queue, in the standard library's FIFO's cycles; queues whose ends start
from registers: the asynchronous queue with a one-entry stage at either end, and the plane
reader's word FIFO. Each keeps every payload, in order, under random valid and ready; the word FIFO
passes a word a cycle."""

import random

import pytest
from amaranth import Module
from amaranth.lib import fifo
from amaranth.sim import Simulator

from gateware.queue import AsyncQueue, Queue
from gateware.store.read_fifo import ReadFifo

#: Unrelated clocks for the asynchronous queue's two ends.
W_PERIOD, R_PERIOD = 8e-9, 5e-9


@pytest.mark.parametrize("depth", [1, 2, 3, 5, 8, 17])
@pytest.mark.parametrize("write_chance,ready_chance", [(0.9, 0.3), (0.5, 0.5), (0.3, 0.9)])
def test_queue_in_the_standard_fifos_cycles(depth, write_chance, ready_chance, seed):
    """The queue and :class:`amaranth.lib.fifo.SyncFIFOBuffered`, written and read alike (random
    valid, payload and ready each cycle): the same ``w_stream.ready`` and ``r_stream.valid`` on
    every cycle, the same payload whenever valid, and the fill's thermometer code equal to the
    standard FIFO's level."""
    m = Module()
    m.submodules.dut = dut = Queue(8, depth)
    m.submodules.ref = ref = fifo.SyncFIFOBuffered(width=8, depth=depth)
    rng = random.Random(seed)
    cycles = 600

    async def bench(ctx):
        levels = set()
        for _ in range(cycles):
            valid, ready = rng.random() < write_chance, rng.random() < ready_chance
            payload = rng.randrange(256)
            for end in (dut, ref):
                ctx.set(end.w_stream.valid, valid)
                ctx.set(end.w_stream.payload, payload)
                ctx.set(end.r_stream.ready, ready)
            await ctx.delay(1e-9)
            got = [ctx.get(dut.w_stream.ready), ctx.get(dut.r_stream.valid)]
            assert got == [ctx.get(ref.w_stream.ready), ctx.get(ref.r_stream.valid)]
            if got[1]:
                assert ctx.get(dut.r_stream.payload) == ctx.get(ref.r_stream.payload)
            level = ctx.get(ref.level)
            assert ctx.get(dut.fill) == (1 << level) - 1
            levels.add(level)
            await ctx.tick()
        # the random enables reached empty, and full where writes outpace reads
        assert 0 in levels and (depth in levels or write_chance <= ready_chance)

    sim = Simulator(m)
    sim.add_clock(1e-8)
    sim.add_testbench(bench)
    sim.run()


@pytest.mark.parametrize("staged", [(), ("sync",), ("dmd",), ("sync", "dmd")], ids=lambda s: "+".join(s) or "none")
def test_async_queue_keeps_order(staged, seed):
    """Payloads written in ``sync`` (random pauses) come out in ``dmd`` (random stalls), every one,
    in order, whichever ends have a stage."""
    dut = AsyncQueue(8, 4, w_domain="sync", r_domain="dmd", staged=staged)
    rng = random.Random(seed)
    sent = [rng.randrange(256) for _ in range(120)]
    got = []

    async def writer(ctx):
        for value in sent:
            while rng.random() < 0.3:
                await ctx.tick("sync")
            ctx.set(dut.w_stream.payload, value)
            ctx.set(dut.w_stream.valid, 1)
            await ctx.tick("sync").until(dut.w_stream.ready)
            ctx.set(dut.w_stream.valid, 0)

    async def reader(ctx):
        while len(got) < len(sent):
            ready = rng.random() < 0.7
            ctx.set(dut.r_stream.ready, ready)
            _, _, valid, payload = await ctx.tick("dmd").sample(dut.r_stream.valid, dut.r_stream.payload)
            if valid and ready:
                got.append(payload)

    sim = Simulator(dut)
    sim.add_clock(W_PERIOD, domain="sync")
    sim.add_clock(R_PERIOD, domain="dmd")
    sim.add_testbench(writer)
    sim.add_testbench(reader)
    sim.run_until(len(sent) * 40 * W_PERIOD)
    assert got == sent


def _run_read_fifo(depth, *, write_chance, ready_chance, words, rng):
    """Write ``words`` words (with the given chance a cycle, never more than ``depth`` written and
    not yet taken, as the plane reader keeps count) and take them (``ready`` with the given
    chance): ``(words taken in order, cycle of each take)``."""
    dut = ReadFifo(16, depth)
    taken, cycles = [], []

    async def bench(ctx):
        written = cycle = 0
        while len(taken) < words:
            write = written < words and written - len(taken) < depth and rng.random() < write_chance
            ready = rng.random() < ready_chance
            ctx.set(dut.w_stream.valid, write)
            ctx.set(dut.w_stream.payload, written)
            ctx.set(dut.r_stream.ready, ready)
            _, _, valid, payload = await ctx.tick().sample(dut.r_stream.valid, dut.r_stream.payload)
            if valid and ready:
                taken.append(payload)
                cycles.append(cycle)
            written += write
            cycle += 1
            assert cycle < 20 * words, "the FIFO stopped passing words"

    sim = Simulator(dut)
    sim.add_clock(5e-9)
    sim.add_testbench(bench)
    sim.run()
    return taken, cycles


@pytest.mark.parametrize("write_chance,ready_chance", [(1.0, 0.5), (0.5, 1.0), (0.7, 0.7), (1.0, 1.0)])
def test_read_fifo_keeps_order(write_chance, ready_chance, seed):
    taken, _ = _run_read_fifo(8, write_chance=write_chance, ready_chance=ready_chance, words=300,
                              rng=random.Random(seed))
    assert taken == list(range(300))


def test_read_fifo_passes_a_word_a_cycle():
    """Written every cycle and always taken: the first word three cycles after it is written, then
    one a cycle."""
    taken, cycles = _run_read_fifo(8, write_chance=1.0, ready_chance=1.0, words=100, rng=random.Random(0))
    assert taken == list(range(100))
    assert cycles[0] == 3 and cycles == list(range(3, 103))
