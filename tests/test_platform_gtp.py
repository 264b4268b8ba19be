"""The SFP's PHY pieces: the GTP wrapper's instance against the behavioural ``GTPA1_DUAL`` model
(``sim/hdl/gtpa1_dual.v``: every port and attribute the wrapper sets must exist there, Verilator's
lint says), and the GMII transmit crossing between two 125 MHz clocks a little apart: frames out
equal frames in."""

import random
from types import SimpleNamespace

from amaranth import ClockDomain, Module, Signal
from amaranth.back import verilog as amaranth_verilog
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out
from amaranth.sim import Simulator

from flow.verilog import lint_top
from gateware.platform.gtp import Gtp
from gateware.platform.pins import GmiiTxElastic
from sim.harness.paths import ROOT, build_dir


class _Lane(wiring.Component):
    """The wrapper with its pins as ports (what the lint reads)."""

    tx_code: In(10)
    rx_bits: Out(10)
    ready: Out(1)
    reset: In(1)
    refclk_p: In(1)
    refclk_n: In(1)
    rxp: In(1)
    rxn: In(1)
    txp: Out(1)
    txn: Out(1)

    def elaborate(self, platform):
        m = Module()
        m.domains += [ClockDomain("gtp_tx"), ClockDomain("gtp_rx")]
        pads = SimpleNamespace(tx=SimpleNamespace(p=self.txp, n=self.txn), rx=SimpleNamespace(p=self.rxp, n=self.rxn))
        refclk = SimpleNamespace(p=self.refclk_p, n=self.refclk_n)
        m.submodules.gtp = gtp = Gtp(pads, refclk, self.reset)
        m.d.comb += [gtp.tx_code.eq(self.tx_code), self.rx_bits.eq(gtp.rx_bits), self.ready.eq(gtp.ready)]
        # something in each user domain, so that both clocks are used
        word = Signal(10)
        m.d.gtp_rx += word.eq(gtp.rx_bits)
        return m


def test_wrapper_lints_against_the_model():
    out = build_dir("test_platform_gtp")
    out.mkdir(parents=True, exist_ok=True)
    path = out / "gtp_lane.v"
    path.write_text(amaranth_verilog.convert(_Lane(), name="gtp_lane", emit_src=False))
    text = path.read_text()
    assert "GTPA1_DUAL #(" in text and ".PLL_DIVSEL_FB_0(32'd2)" in text and ".PLL_TXDIVSEL_OUT_0(32'd2)" in text
    model = (ROOT / "sim" / "hdl" / "gtpa1_dual.v").read_text()
    ok, messages = lint_top(path, "gtp_lane", [model], workdir=out)
    assert ok, messages


def _frames(rng, count):
    return [bytes(rng.randrange(256) for _ in range(rng.randrange(8, 80))) for _ in range(count)]


def _run_elastic(i_ns, o_ns, seed):
    rng = random.Random(seed)
    frames = _frames(rng, 30)
    m = Module()
    m.domains += [ClockDomain("a"), ClockDomain("b")]
    m.submodules.elastic = dut = GmiiTxElastic("a", "b")
    sim = Simulator(m)
    sim.add_clock(i_ns * 1e-9, domain="a")
    sim.add_clock(o_ns * 1e-9, domain="b")
    got = []

    async def send(ctx):
        for _ in range(30):
            await ctx.tick("a")
        for frame in frames:
            for byte in frame:
                ctx.set(dut.i.en, 1)
                ctx.set(dut.i.d, byte)
                await ctx.tick("a")
            ctx.set(dut.i.en, 0)
            for _ in range(12):                      # the minimum inter-frame gap
                await ctx.tick("a")

    async def receive(ctx):
        frame = bytearray()
        async for _clk, _rst, en, d in ctx.tick("b").sample(dut.o.en, dut.o.d):
            if en:
                frame.append(d)
            elif frame:
                got.append(bytes(frame))
                frame = bytearray()

    sim.add_testbench(send)
    sim.add_process(receive)
    total = sum(len(f) + 12 for f in frames) + 80
    sim.run_until(total * max(i_ns, o_ns) * 1e-9)
    return frames, got


def test_tx_crossing_slower_and_faster_reader():
    # 1% apart each way, fifty times the 1000BASE-X tolerance (200 ppm), so that over 30 frames
    # the FIFO drops or adds idles many times over
    for i_ns, o_ns in ((8.0, 8.08), (8.08, 8.0)):
        frames, got = _run_elastic(i_ns, o_ns, seed=int(i_ns * 1000))
        assert got == frames, (i_ns, o_ns)
