"""The command bus alone (Amaranth simulator): a row load that waits for its data from the store
is counted once, however many cycles it waits; rows whose data is there are not counted."""

from amaranth import Cat

from gateware.dlpc410.bus import Bus
from gateware.dlpc410.interface import RowMode
from sim.harness.amaranth_sim import simulate
from spec.facts import TEST_DMD
from spec.schedule import row_cycles

DMD = TEST_DMD


def test_underruns_count_rows_not_cycles(test_name):
    dut = Bus(DMD)
    R = row_cycles(DMD, 1)
    rows = DMD.rows_per_block
    # the store holds back the data of these rows for many row cycles after the row before starts
    starved = {3, 4, 10}
    hold = 6 * R
    seen = []

    async def bench(ctx):
        ctx.set(dut.regs.row_period, R)
        ctx.set(dut.running, 1)
        ctx.set(dut.planner.writable, (1 << DMD.blocks) - 1)
        ctx.set(dut.loads.payload, {"group": 0, "mask": 1, "first": 0, "last": 0, "first_row": 0, "first_occupied": 1,
                                    "single": 0})
        ctx.set(dut.loads.valid, 1)
        ctx.set(dut.beats.valid, 1)
        ctx.set(dut.row_ready, 1)
        now, dark_until = 0, -1
        while len(seen) < rows and now < 200 * rows * R:
            ctx.set(dut.even, now % 2 == 0)
            ctx.set(dut.row_ready, int(now >= dark_until))
            await ctx.tick()
            now += 1
            cmd = ctx.get(dut.command)
            # a row's command is held through its row cycle: a new address is a new row
            if ctx.get(dut.dvalid) and cmd.rowmd == RowMode.ADDRESSED and (not seen or seen[-1][1] != cmd.rowad):
                seen.append((now, int(cmd.rowad)))
                if len(seen) in starved:       # the next row's data is late
                    dark_until = now + hold
        ctx.set(dut.loads.valid, 0)
        for _ in range(2 * R):
            await ctx.tick()
        assert [row for _, row in seen] == list(range(rows))
        waited = [k for k in range(1, rows) if seen[k][0] - seen[k - 1][0] > R]
        assert waited == sorted(starved), waited
        assert ctx.get(dut.underruns) == len(starved)

    simulate(dut, [bench], name=test_name, deadline=1e-3)


def test_lowest_due_and_its_flag(test_name):
    """The pulse the bus chooses is the lowest due group, and ``lowest_due_has`` answers that
    group's flag: against the lowest set bit, for random due and flag vectors (some all clear)."""
    import random

    from amaranth import Module, Signal

    from gateware.dlpc410.due import lowest_due, lowest_due_has

    G = 16
    due, flags = Signal(G), Signal(G)
    fours = Signal(G // 4)
    lowest, has = Signal(G), Signal()
    m = Module()
    m.d.comb += [fours.eq(Cat(due[q:q + 4].any() for q in range(0, G, 4))),
                 lowest.eq(lowest_due(due, fours)), has.eq(lowest_due_has(due, fours, flags))]
    rng = random.Random(3)
    cases = [(0, rng.getrandbits(G))] + [(rng.getrandbits(G) & rng.getrandbits(G), rng.getrandbits(G))
                                         for _ in range(3000)]

    async def bench(ctx):
        for d, f in cases:
            ctx.set(due, d)
            ctx.set(flags, f)
            low = d & -d                       # the lowest set bit (0: none)
            assert ctx.get(lowest) == low
            assert ctx.get(has) == (1 if f & low else 0)
    simulate(m, [bench], name=test_name, clocks={}, waves=False)
