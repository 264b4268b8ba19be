"""The DCLK 400 MHz lanes: the core's four edges per ``dmd`` cycle through the platform's 4:1
serialisers (behavioural OSERDES2 model), read back at every edge of the serialised DCLK: each
pin's bits arrive in order, one per DCLK edge, rising edge first, with no bit lost or repeated."""

import random

from amaranth import Module, Signal
from amaranth.lib import data
from amaranth.sim import Simulator

from gateware.platform.serdes import DCLK_BITS, lane_bits
from sim.models.oserdes2_model import Oserdes2Model

DMD_NS = 5.0
IO_NS = DMD_NS / 4


def test_lanes_in_order_at_every_dclk_edge():
    m = Module()
    pins = 3
    edges = Signal(data.ArrayLayout(pins, 4))         # three pins of one bus, four edges a cycle
    strobe = Signal()
    lanes = {}
    for pin in range(pins):
        lane = m.submodules[f"din{pin}"] = Oserdes2Model("io")
        m.d.comb += lane.strobe.eq(strobe)
        for i, bit in enumerate(lane_bits(edges, pin)):
            m.d.comb += lane.d[i].eq(bit)
        lanes[pin] = lane.out
    dclk = m.submodules.dclk = Oserdes2Model("io_dclk")
    dclk_strobe = Signal()
    m.d.comb += [dclk.d.eq(sum(b << i for i, b in enumerate(DCLK_BITS))), dclk.strobe.eq(dclk_strobe)]
    # the BUFPLL strobe: one I/O clock cycle after each dmd edge (both I/O clocks keep their own)
    phase = Signal(2)
    m.d.io += phase.eq(phase + 1)
    m.d.comb += strobe.eq(phase == 0)
    phase_dclk = Signal(2)
    m.d.io_dclk += phase_dclk.eq(phase_dclk + 1)
    m.d.comb += dclk_strobe.eq(phase_dclk == 0)

    sim = Simulator(m)
    sim.add_clock(DMD_NS * 1e-9, domain="dmd")
    sim.add_clock(IO_NS * 1e-9, domain="io")
    # DCLK's lane runs half a bit later: its edges fall in the middle of the data bits
    sim.add_clock(IO_NS * 1e-9, domain="io_dclk", phase=IO_NS / 2 * 1e-9)
    rng = random.Random(7)
    cycles = 40
    sent = [[[rng.getrandbits(1) for _ in range(4)] for _ in range(pins)] for _ in range(cycles)]
    seen = {pin: [] for pin in range(pins)}

    async def drive(ctx):
        for cycle in range(cycles):
            for pin in range(pins):
                for e in range(4):
                    ctx.set(edges[e][pin], sent[cycle][pin][e])
            await ctx.tick("dmd")
        await ctx.tick("dmd").repeat(4)

    async def sample(ctx):
        last = 0
        async for value, *bits in ctx.changed(dclk.out).sample(*lanes.values()):
            kind = "rise" if value and not last else "fall" if last and not value else None
            last = value
            if kind:
                for pin in range(pins):
                    seen[pin].append((kind, bits[pin]))

    sim.add_testbench(drive)
    sim.add_process(sample)
    sim.run()

    for pin in range(pins):
        kinds = [k for k, _ in seen[pin]]
        bits = [b for _, b in seen[pin]]
        want = [b for cycle in sent for b in cycle[pin]]
        # DCLK edges alternate, and the bits read at them are the edges sent, in order, after
        # the serialiser's fixed latency
        assert all(a != b for a, b in zip(kinds, kinds[1:], strict=False))
        start = next(i for i in range(len(bits)) if bits[i:i + len(want)] == want)
        assert kinds[start] == "rise", "edge 0 of a cycle is read at a rising DCLK edge"
        assert bits[start:start + len(want)] == want
