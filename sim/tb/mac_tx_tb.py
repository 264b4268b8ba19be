"""cocotb testbench of the transmit MAC's generated Verilog (:class:`gateware.mac.axis.AxisTransmitter`):
cocotbext-axi's AxiStreamSource on ``s_axis_*`` (``sync``), cocotbext-eth's GmiiSink on the pins.

GmiiSink does not keep the first byte of a burst (the first preamble byte), so frames are
compared by their payload after the SFD, never by raw offsets.

Run by ``tests/test_mac_tx_verilog.py``.
"""

import itertools

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, with_timeout
from cocotbext.axi import AxiStreamBus, AxiStreamFrame, AxiStreamSource
from cocotbext.eth import GmiiSink

from sim.models import mac_model as mac

CLOCK_NS = 8


async def start(dut, sync_ns):
    cocotb.start_soon(Clock(dut.gmii_tx_clk, CLOCK_NS, unit="ns").start())
    cocotb.start_soon(Clock(dut.clk, sync_ns, unit="ns").start())
    dut.rst.value = 1
    dut.gmii_tx_rst.value = 1
    await ClockCycles(dut.clk, 4)
    dut.rst.value = 0
    dut.gmii_tx_rst.value = 0
    await ClockCycles(dut.clk, 4)
    source = AxiStreamSource(AxiStreamBus.from_prefix(dut, "s_axis"), dut.clk, dut.rst)
    sink = GmiiSink(dut.gmii_txd, dut.gmii_tx_er, dut.gmii_tx_en, dut.gmii_tx_clk)
    return source, sink


def padded(frame):
    return frame + bytes(max(0, 60 - len(frame)))


async def send_and_check(dut, frames, *, sync_ns, aborts=()):
    source, sink = await start(dut, sync_ns)
    for i, frame in enumerate(frames):
        user = [0] * (len(frame) - 1) + [int(i in aborts)]
        await source.send(AxiStreamFrame(frame, tuser=user))
    received = []
    for _ in frames:
        received.append(await with_timeout(sink.recv(), 2, "ms"))
    for i, (frame, got) in enumerate(zip(frames, received, strict=True)):
        assert got.error is None, f"frame {i}: tx_er on the wire"
        assert got.get_preamble()[-1] == 0xD5
        assert bytes(got.get_payload()) == padded(frame), f"frame {i}: payload differs"
        assert got.check_fcs() == (i not in aborts), f"frame {i}: FCS"
    # Frames queued behind each other leave at the minimum gap, never closer.
    gaps = [(b.sim_time_start - a.sim_time_end) // (CLOCK_NS * 1000)
            for a, b in zip(received, received[1:], strict=False)]
    assert min(gaps) >= 12, gaps
    assert int(dut.underruns.value) == 0
    return gaps


@cocotb.test()
async def frames_at_line_rate(dut):
    """Runts to jumbo frames from a 125 MHz producer: padded, FCS right; frames already buffered
    follow at exactly the minimum gap (a long frame waits until it is buffered)."""
    rng = mac.seeded(60)
    frames = [bytes([1, 2, 3]), mac.udp_frame(b"")] + [mac.frame_of_length(n, rng)[:-4]
                                                         for n in (64, 65, 1518, 9018, 100)]
    gaps = await send_and_check(dut, frames, sync_ns=8)
    assert gaps[:2] == [12, 12] and gaps[-1] == 12, gaps


@cocotb.test()
async def abort_and_slow_producer(dut):
    """A 100 MHz producer and an aborted frame: whole frames buffered, so no underrun; the aborted
    frame leaves with a bad FCS and its neighbours are intact."""
    rng = mac.seeded(61)
    frames = [mac.frame_of_length(n, rng)[:-4] for n in (200, 64, 1500, 80)]
    await send_and_check(dut, frames, sync_ns=10, aborts={1})


@cocotb.test()
async def underrun_of_a_frame_longer_than_the_fifo(dut):
    """A 6,000-byte frame (longer than the 2,048-byte FIFO) from a producer at half the line rate
    runs dry mid-frame: tx_er goes out, the underrun is counted, and the next frame is intact."""
    source, sink = await start(dut, 8)
    source.set_pause_generator(itertools.cycle([0, 1]))
    rng = mac.seeded(62)
    long_frame, after = mac.frame_of_length(6004, rng)[:-4], mac.frame_of_length(100, rng)[:-4]
    await source.send(AxiStreamFrame(long_frame))
    await source.send(AxiStreamFrame(after))
    cut = await with_timeout(sink.recv(), 2, "ms")
    good = await with_timeout(sink.recv(), 2, "ms")
    assert cut.error is not None and any(cut.error), "no tx_er on the cut frame"
    assert len(cut.get_payload(strip_fcs=False)) < len(long_frame)
    assert bytes(good.get_payload()) == after and good.check_fcs() and good.error is None
    await ClockCycles(dut.clk, 10)
    assert int(dut.underruns.value) == 1
