"""The register crossing (:class:`gateware.dlpc410.register_crossing.RegisterCrossing`) in the Amaranth simulator:
register sets from ``sync`` reach ``dmd`` whole, in order, only while the sequencer rests; a set
still in the mailbox when a newer one comes is replaced and counted."""

import random

from amaranth.lib import data

from gateware.dlpc410.register_crossing import RegisterCrossing
from gateware.registers import Registers, TriggerMode
from sim.harness.amaranth_sim import simulate

LAYOUT = data.Layout.cast(Registers)


def register_set(rng):
    """A random set, every bit of it random (the crossing must not care what the bits mean)."""
    return rng.getrandbits(LAYOUT.size)




def test_sets_cross_whole_in_order_at_rest(test_name):
    rng = random.Random(6)
    power_up = register_set(rng)
    dut = RegisterCrossing(data.Const(LAYOUT, power_up))
    sent = [register_set(rng) for _ in range(12)]
    seen = {"values": [], "reloads": [], "done": False}

    async def host(ctx):
        # a burst of four on consecutive cycles (the mailbox keeps the newest), then sets one by one
        for index, value in enumerate(sent):
            ctx.set(dut.sets.payload, data.Const(LAYOUT, value))
            ctx.set(dut.sets.valid, 1)
            await ctx.tick()
            ctx.set(dut.sets.valid, 0)
            if index >= 3:
                await ctx.tick().repeat(rng.randrange(1, 60))
        await ctx.tick().repeat(400)
        seen["superseded"] = ctx.get(dut.superseded)
        seen["done"] = True

    async def sequencer(ctx):
        srng = random.Random(7)
        previous = power_up
        while not seen["done"]:
            rest = srng.random() < 0.1
            ctx.set(dut.at_rest, rest)
            _clk, _rst, reload, regs = await ctx.tick("dmd").sample(dut.reload, dut.regs)
            value = regs.as_value().value
            assert value == previous, "the registers changed other than in the cycle after a reload"
            if reload:
                assert rest, "a set was applied while the sequencer was not at rest"
                seen["reloads"].append(len(seen["values"]))
            new = ctx.get(dut.regs).as_value().value
            if new != previous:
                assert reload, "the registers changed without a reload"
                seen["values"].append(new)
            previous = new
        seen["applied"] = ctx.get(dut.applied)

    simulate(dut, [host, sequencer], name=test_name, clocks={"sync": 125e6, "dmd": 200e6}, deadline=1e-4)
    values = seen["values"]
    # whole sets only, in the order sent, the last one always among them
    assert all(v in sent for v in values)
    assert [sent.index(v) for v in values] == sorted(sent.index(v) for v in values)
    assert values[-1] == sent[-1]
    # the burst of four on consecutive cycles: the first two leave the mailbox for the FIFO (two
    # deep), the third is replaced by the fourth while the FIFO is full, unless the sequencer
    # rested in between; every set is either applied or counted as replaced, and the sets sent
    # one by one, with time to cross, are all applied
    assert seen["applied"] == len(values) == len(seen["reloads"])
    assert seen["applied"] + seen["superseded"] == len(sent)
    assert seen["superseded"] >= 1
    assert values[-len(sent[4:]):] == sent[4:]


def _gated(value, armed):
    """A set as the sequencer sees it: disarmed, its trigger mode software and ``chain`` low."""
    if armed:
        return value
    chain, trigger = LAYOUT["chain"], LAYOUT["trigger"]
    value &= ~(1 << chain.offset) & ~(((1 << trigger.width) - 1) << trigger.offset)
    return value | (TriggerMode.SOFTWARE.value << trigger.offset)


def test_disarmed_the_trigger_reads_software_and_frames_unchained(test_name):
    """Arming toggled at random while sets arrive and apply: on every cycle the registers are the
    set applied last, with the trigger mode software and ``chain`` low whenever the cycle before
    was disarmed; from reset too (disarmed at power-up)."""
    rng = random.Random(9)
    chain, trigger = LAYOUT["chain"], LAYOUT["trigger"]

    def chained_set():
        # chained and triggered by something other than software, so that arming shows
        hardware = rng.choice([m for m in TriggerMode if m != TriggerMode.SOFTWARE]).value
        value = register_set(rng) & ~(((1 << trigger.width) - 1) << trigger.offset)
        return value | (1 << chain.offset) | (hardware << trigger.offset)

    power_up = chained_set()
    dut = RegisterCrossing(data.Const(LAYOUT, power_up), armed=False)
    sent = [chained_set() for _ in range(8)]
    seen = {"done": False, "cycles": {False: 0, True: 0}, "reloads": 0}

    async def host(ctx):
        for value in sent:
            ctx.set(dut.sets.payload, data.Const(LAYOUT, value))
            ctx.set(dut.sets.valid, 1)
            await ctx.tick()
            ctx.set(dut.sets.valid, 0)
            await ctx.tick().repeat(rng.randrange(40, 80))
        await ctx.tick().repeat(100)
        seen["done"] = True

    async def sequencer(ctx):
        srng = random.Random(10)
        applied, armed = power_up, False
        assert ctx.get(dut.regs).as_value().value == _gated(power_up, False)
        while not seen["done"]:
            if srng.random() < 0.05:
                armed = not armed
            ctx.set(dut.armed, armed)
            ctx.set(dut.at_rest, srng.random() < 0.3)
            _clk, _rst, reload = await ctx.tick("dmd").sample(dut.reload)
            if reload:
                applied = sent[seen["reloads"]]
                seen["reloads"] += 1
            assert ctx.get(dut.regs).as_value().value == _gated(applied, armed)
            seen["cycles"][armed] += 1

    simulate(dut, [host, sequencer], name=test_name, clocks={"sync": 125e6, "dmd": 200e6}, deadline=1e-4)
    assert seen["reloads"] == len(sent)
    assert min(seen["cycles"].values()) > 100
