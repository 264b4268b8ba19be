"""cocotb testbench of the receive MAC's generated Verilog
(:class:`gateware.mac.axis.AxisReceiver`): cocotbext-eth's GmiiSource on the pins, cocotbext-axi's
AxiStreamSink on ``m_axis_*``, frames built by scapy, verdicts checked against
:func:`sim.models.mac_model.receive`.

Run by ``tests/test_mac_rx_verilog.py``.
"""

import itertools

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, RisingEdge, with_timeout
from cocotbext.axi import AxiStreamBus, AxiStreamSink
from cocotbext.eth import GmiiFrame, GmiiSource

from gateware.mac.gmii_rx import counters_layout
from sim.harness.cocotb_run import params
from sim.harness.layout import unpack
from sim.models import mac_model as mac

CLOCK_NS = 8


class Bench:
    """The DUT after a reset, with a GMII source, an AXI-Stream sink and the counters."""

    def __init__(self, dut):
        self.dut = dut
        self.source = GmiiSource(dut.gmii_rxd, dut.gmii_rx_er, dut.gmii_rx_dv, dut.gmii_rx_clk)
        self.sink = AxiStreamSink(AxiStreamBus.from_prefix(dut, "m_axis"), dut.clk, dut.rst)

    @classmethod
    async def start(cls, dut, *, sync_ps=CLOCK_NS * 1000):
        cocotb.start_soon(Clock(dut.gmii_rx_clk, CLOCK_NS, unit="ns").start())
        cocotb.start_soon(Clock(dut.clk, sync_ps, unit="ps").start())
        dut.rst.value = 1
        dut.gmii_rx_rst.value = 1
        await ClockCycles(dut.clk, 4)
        dut.rst.value = 0
        dut.gmii_rx_rst.value = 0
        await ClockCycles(dut.clk, 4)
        return cls(dut)

    async def send(self, frames):
        """``frames``: GmiiFrame or bytes (a frame with FCS, sent with the standard preamble)."""
        for frame in frames:
            if not isinstance(frame, GmiiFrame):
                frame = GmiiFrame.from_raw_payload(frame)
            await self.source.send(frame)
        await self.source.wait()

    async def settle(self):
        """Wait until the line is quiet and everything received has left the MAC."""
        await self.source.wait()
        quiet = 0
        while quiet < 64:
            await RisingEdge(self.dut.clk)
            quiet = 0 if int(self.dut.m_axis_tvalid.value) else quiet + 1

    def received(self):
        """Frames taken so far, as (bytes, bad)."""
        out = []
        while not self.sink.empty():
            frame = self.sink.recv_nowait()
            user = frame.tuser if isinstance(frame.tuser, int) else frame.tuser[-1]
            out.append((bytes(frame.tdata), bool(user)))
        return out

    def counters(self):
        values = unpack(counters_layout(), self.dut.counters.value.to_unsigned())
        return values, int(self.dut.dropped.value)


def symbols_of(frame):
    """The model's GMII symbols for a GmiiFrame (its data and error lists)."""
    frame = GmiiFrame(frame)
    frame.normalize()
    return [(b, 1, e) for b, e in zip(frame.data, frame.error, strict=True)]


async def expect(bench, frames, *, timeout_ms=5):
    """Send ``frames`` back to back; check outputs and counters against the model."""
    gmii_frames = [f if isinstance(f, GmiiFrame) else GmiiFrame.from_raw_payload(f) for f in frames]
    symbols = []
    for f in gmii_frames:
        symbols += symbols_of(f) + mac.idle(12)
    expected = mac.receive(symbols, params().get("max_frame", 9018))
    await with_timeout(bench.send(gmii_frames), timeout_ms, "ms")
    await bench.settle()
    got = bench.received()
    want = [(r.data, r.bad) for r in expected if r.data]
    assert [(len(f), bad) for f, bad in got] == [(len(f), bad) for f, bad in want]
    assert got == want, "frame contents differ from the model"
    counters, dropped = bench.counters()
    assert counters == mac.counts(expected), (counters, mac.counts(expected))
    assert dropped == 0
    return expected, got


async def expect_one_bad(dut, bad, verdict):
    """A good frame, the bad one, a good frame: the counter of ``verdict`` is 1, both good
    frames arrive, and no frame passed as good carries the bad frame's bytes."""
    bench = await Bench.start(dut)
    good = mac.frame_of_length(100, mac.seeded(40))
    _, got = await expect(bench, [good, bad, good])
    counters, _ = bench.counters()
    assert counters[verdict] == 1 and counters["good"] == 2, counters
    assert [f for f, b in got if not b] == [good[:-4]] * 2
    content = bytes(GmiiFrame(bad).data)
    assert not any(not b and f and f in content for f, b in got if f != good[:-4])


@cocotb.test()
async def good_traffic_back_to_back(dut):
    """64 to 9,018-byte frames with random payloads at the minimum gap: every one arrives intact."""
    bench = await Bench.start(dut)
    rng = mac.seeded(41)
    sizes = mac.random_sizes(rng, 40, jumbo=[9018, 9000, 8000])
    rng.shuffle(sizes)
    frames = [mac.frame_of_length(n, rng) for n in sizes]
    _, got = await expect(bench, frames, timeout_ms=20)
    assert got == [(f[:-4], False) for f in frames]


def good_frame(seed, length=300):
    return mac.frame_of_length(length, mac.seeded(seed))


@cocotb.test()
async def bad_fcs(dut):
    frame = bytearray(good_frame(42))
    frame[-1] ^= 0x01
    await expect_one_bad(dut, bytes(frame), "bad_fcs")


def with_error(frame, index):
    g = GmiiFrame.from_raw_payload(frame)
    g.error = [int(i == index) for i in range(len(g.data))]
    return g


@cocotb.test()
async def rx_er_at_start(dut):
    await expect_one_bad(dut, with_error(good_frame(43), 8), "rx_er")


@cocotb.test()
async def rx_er_in_middle(dut):
    await expect_one_bad(dut, with_error(good_frame(44), 8 + 150), "rx_er")


@cocotb.test()
async def rx_er_in_fcs(dut):
    await expect_one_bad(dut, with_error(good_frame(45), 8 + 300 - 1), "rx_er")


@cocotb.test()
async def runt(dut):
    await expect_one_bad(dut, good_frame(46, 60), "runt")


@cocotb.test()
async def oversize(dut):
    await expect_one_bad(dut, good_frame(47, params().get("max_frame", 9018) + 1), "oversize")


@cocotb.test()
async def truncated_preamble_accepted(dut):
    """One or two preamble bytes (or none) before the SFD: the frame is still good."""
    bench = await Bench.start(dut)
    frames = [GmiiFrame(bytes([0x55] * n + [0xD5]) + good_frame(48 + n, 64)) for n in (0, 1, 2)]
    _, got = await expect(bench, frames)
    assert [b for _, b in got] == [False] * 3


@cocotb.test()
async def preamble_wrong_byte(dut):
    frame = GmiiFrame(bytes([0x55, 0x55, 0x5D, 0x55, 0x55, 0x55, 0x55, 0xD5]) + good_frame(51))
    await expect_one_bad(dut, frame, "preamble")


@cocotb.test()
async def missing_sfd(dut):
    """Preamble straight into the frame, no SFD: a preamble error, nothing forwarded."""
    frame = GmiiFrame(bytes([0x55] * 7) + good_frame(52))
    await expect_one_bad(dut, frame, "preamble")


@cocotb.test()
async def slow_consumer_drops_whole_frames(dut):
    """The AXI-Stream consumer takes one byte in four: frames are dropped whole and counted, and
    every frame passed as good is a sent one, intact and in order."""
    bench = await Bench.start(dut)
    bench.sink.set_pause_generator(itertools.cycle([1, 1, 1, 0]))
    rng = mac.seeded(53)
    frames = [mac.frame_of_length(1518, rng) for _ in range(params().get("slow_frames", 30))]
    await with_timeout(bench.send(frames), 20, "ms")
    await bench.settle()
    got = bench.received()
    counters, dropped = bench.counters()
    sent = iter(f[:-4] for f in frames)
    good = [f for f, bad in got if not bad]
    assert all(any(g == s for s in sent) for g in good), "a good frame altered or out of order"
    assert len(got) == len(good), "a frame arrived cut or flagged"
    assert dropped > 0 and len(good) + dropped == len(frames), (len(good), dropped)
    assert counters["good"] == len(frames)
