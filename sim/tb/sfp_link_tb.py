"""cocotb testbench of the SVEC's Ethernet on its generated Verilog (:mod:`sim.tb.sfp_link`):
the MAC, our PCS and the GTP lane's model against a Python link partner
(:class:`sim.models.pcs_partner.Partner`) on a clock of its own, over the serial line.

One run goes through the link's life, each step an assertion: auto-negotiation completes both
ways; frames cross back to back in both directions, every byte and FCS checked, the clocks'
offsets absorbed between frames; bit errors give bad frames, counted, never a wrong frame
handed on as good; a comma slip loses sync, is counted and the link comes back; the partner's
restart of negotiation is counted and the link comes back. The measured times and counts go
to ``results.json`` in the run directory when ``DUT_PARAMS`` names it (the benchmark).

Run by ``tests/test_sfp_link_verilog.py`` and :mod:`sim.bench.pcs_figures`.
"""

import json
import logging
import random

import cocotb
from cocotb.triggers import FallingEdge, Timer, with_timeout
from cocotbext.axi import AxiStreamBus, AxiStreamFrame, AxiStreamSink, AxiStreamSource
from scapy.layers.inet import IP, UDP
from scapy.layers.l2 import Ether

from sim.harness.cocotb_run import params
from sim.models.pcs_partner import PREAMBLE, Partner, with_fcs
from sim.tb.sfp_link import LINK_TIMER

DATA = 2            # Xmit.DATA
BOARD_MAC, PARTNER_MAC = "02:00:00:00:00:01", "02:00:00:00:00:02"


def random_frames(rng, count):
    """``count`` UDP frames of random lengths, 64 to 1518 bytes with the FCS (scapy-built)."""
    frames = []
    for _ in range(count):
        length = rng.randrange(64, 1519) - 4
        head = Ether(dst=PARTNER_MAC, src=BOARD_MAC) / IP(src="10.0.0.1", dst="10.0.0.2") / UDP(sport=9, dport=9)
        payload = bytes(rng.randrange(256) for _ in range(length - len(head)))
        frames.append(bytes(head / payload))
    return frames


class Bench:
    """The partner's two clocks and the MAC's streams, running."""

    def __init__(self, dut, offset):
        self.dut = dut
        self.partner = Partner(link_timer=LINK_TIMER, offset=offset)
        self.source = AxiStreamSource(AxiStreamBus.from_prefix(dut, "s_axis"), dut.core_clk_n)
        self.sink = AxiStreamSink(AxiStreamBus.from_prefix(dut, "m_axis"), dut.core_clk_n)
        self.rx_words = 0
        for stream in (self.source, self.sink):
            stream.log.setLevel(logging.WARNING)
        cocotb.start_soon(self._transmit())
        cocotb.start_soon(self._receive())

    async def _transmit(self):
        while True:
            # half a cycle from the edge that takes it
            await FallingEdge(self.dut.partner_tx_clk)
            self.dut.partner_tx.value = self.partner.transmit_word()

    async def _receive(self):
        while True:
            await FallingEdge(self.dut.partner_rx_clk)
            self.partner.receive_word(int(self.dut.partner_rx.value))
            self.rx_words += 1

    def drain(self):
        """Drop the frames the MAC gave so far (a frame cut by a loss of sync)."""
        while not self.sink.empty():
            self.sink.recv_nowait()

    def board(self, name):
        return int(getattr(self.dut, name).value)

    def counters(self):
        value = int(self.dut.counters.value)
        names = ("good", "bad_fcs", "rx_er", "runt", "oversize", "preamble")
        return {name: value >> (32 * i) & 0xFFFFFFFF for i, name in enumerate(names)}

    def link_up(self):
        return self.partner.link_ok and self.board("an_complete") and self.board("xmit") == DATA \
            and self.board("sync_status")

    async def wait(self, condition, timeout_us, what):
        for _ in range(int(timeout_us * 10)):
            if condition():
                return cocotb.utils.get_sim_time("us")
            await Timer(100, "ns")
        raise AssertionError(f"{what}: not within {timeout_us} us ({self.state()})")

    def state(self):
        partner = self.partner
        board = {name: self.board(name) for name in ("sync_status", "an_complete", "xmit", "losses", "slips",
                                                      "restarts")}
        return (f"partner: {partner.an.state}, sync {partner.sync.state}, {partner.invalid} invalid, "
                f"{partner.realigns} realigns, "
                f"{self.rx_words} words; board: {board}")

    async def to_partner(self, frames, timeout_us):
        """Frames the board's MAC sends, as the partner receives them (preamble, SFD, FCS)."""
        before = len(self.partner.frames)
        start = cocotb.utils.get_sim_time("us")
        for frame in frames:
            await self.source.send(AxiStreamFrame(frame))
        await self.wait(lambda: len(self.partner.frames) - before >= len(frames), timeout_us, "frames to the partner")
        end = cocotb.utils.get_sim_time("us")
        return self.partner.frames[before:before + len(frames)], end - start

    async def from_partner(self, frames, timeout_us, expected=None):
        """Frames the partner sends, as the board's MAC gives them: (data, bad) each."""
        for frame in frames:
            self.partner.send(frame)
        got = []
        for _ in range(len(frames) if expected is None else expected):
            frame = await with_timeout(self.sink.recv(), timeout_us, "us")
            got.append((bytes(frame.tdata), bad_of(frame)))
        return got


def first_difference(got, want):
    return next((n for n, (a, b) in enumerate(zip(got, want, strict=False)) if a != b), min(len(got), len(want)))


def bad_of(frame):
    """The MAC's verdict on a received frame: ``tuser`` on its last byte (one value for all)."""
    user = frame.tuser
    return bool(user[-1] if isinstance(user, list) and user else user)


def check_at_partner(sent, received):
    """The partner's frames from /S/: a preamble (a transmitter may shorten it by a byte to start
    on an even code-group), the SFD, the frame and its FCS."""
    for i, (frame, got) in enumerate(zip(sent, received, strict=True)):
        start = got.find(PREAMBLE[-1])
        assert start >= 6 and set(got[:start]) == {PREAMBLE[0]}, f"frame {i}: preamble {got[:start + 1].hex()}"
        want = with_fcs(frame)
        body = got[start + 1:]
        assert body == want, f"frame {i} ({len(want)} bytes): differs at the partner from byte " \
            f"{first_difference(body, want)} " \
            f"({len(body)} bytes received)"


def check_at_board(sent, received):
    for i, (frame, (data, bad)) in enumerate(zip(sent, received, strict=True)):
        assert not bad and data == frame, f"frame {i} ({len(frame) + 4} bytes): differs at the board from byte " \
            f"{first_difference(data, frame)} ({len(data)} bytes received, bad {bad})"


@cocotb.test()
async def link_life(dut):
    p = params()
    rng = random.Random(p.get("seed", 1))
    count = p.get("frames", 4)
    results = {}
    bench = Bench(dut, p.get("offset", 5))
    dut.s_axis_tvalid.value = 0

    # auto-negotiation, both ways
    results["link_up_us"] = await bench.wait(bench.link_up, 400, "link up after power-on")
    assert bench.partner.an.lp_ability & 0x20, "the partner did not read the board's full duplex"
    assert bench.board("sync_status") == 1
    invalid = bench.partner.invalid

    # frames both ways, back to back at line rate, offsets absorbed between frames
    out = random_frames(rng, count)
    received, elapsed = await bench.to_partner(out, 40 * count)
    results["tx_lost"] = sum(got[-len(f) - 4:] != with_fcs(f) for f, got in zip(out, received, strict=True))
    check_at_partner(out, received)
    assert bench.partner.bad_frames == 0 and bench.partner.invalid == invalid, "code-groups invalid at the partner"
    results["tx_bytes"], results["tx_us"] = sum(len(f) + 4 for f in out), elapsed
    back = random_frames(rng, count)
    start = cocotb.utils.get_sim_time("us")
    got = await bench.from_partner(back, 40 * count)
    results["rx_lost"] = sum(bad or data != frame for frame, (data, bad) in zip(back, got, strict=True))
    check_at_board(back, got)
    results["rx_bytes"], results["rx_us"] = sum(len(f) + 4 for f in back), cocotb.utils.get_sim_time("us") - start
    await Timer(1, "us")        # the counters' crossing into sync
    assert bench.counters()["good"] == count and bench.board("rx_dropped") == 0
    assert bench.board("tx_underruns") == 0

    # bit errors: one bit of a data code-group flipped in every other frame
    before = bench.counters()
    frames = random_frames(rng, 2 * p.get("errors", 2))
    for i, frame in enumerate(frames):
        bench.partner.send(frame, flip=rng.randrange(len(frame)) if i % 2 else None)
    await bench.wait(lambda: not bench.partner._frames, 40 * len(frames), "the partner sending")
    await Timer(30, "us")
    after = bench.counters()
    bad = sum(after[n] - before[n] for n in ("bad_fcs", "rx_er", "preamble", "runt"))
    good = []
    while not bench.sink.empty():
        frame = bench.sink.recv_nowait()
        if not bad_of(frame):
            good.append(bytes(frame.tdata))
    assert good == frames[::2], "a frame with a bit error was handed on as good, or a good one lost"
    assert after["good"] - before["good"] == len(frames) // 2
    # each frame with an error is counted bad, or (its /S/ or SFD lost) not seen as a frame
    assert 1 <= bad <= len(frames) // 2, f"{bad} bad frames counted for {len(frames) // 2} errors"
    assert after["rx_er"] > before["rx_er"], "no bit error gave RX_ER"
    results["bit_errors"], results["bad_frames"] = len(frames) // 2, bad

    # a comma slip in the middle of a long frame: sync lost, counted, the link comes back
    losses, slips, restarts = bench.board("losses"), bench.board("slips"), bench.board("restarts")
    long = random_frames(random.Random(7), 1)[0][:14] + random.Random(8).randbytes(1500)
    bench.partner.send(long)
    await Timer(3, "us")
    bench.partner.slip()
    await bench.wait(lambda: bench.board("losses") > losses, 40, "sync lost after the slip")
    down = await bench.wait(lambda: not bench.link_up(), 40, "link down after the loss of sync")
    up = await bench.wait(bench.link_up, 400, "link back after the slip")
    assert bench.board("slips") > slips, f"the slip was not counted ({slips}: {bench.state()})"
    bench.drain()
    results["relink_us"] = up - down
    frames = random_frames(rng, 2)
    check_at_board(frames, await bench.from_partner(frames, 80))
    assert bench.board("restarts") > restarts

    # the partner restarts negotiation: a zero base page, then its abilities again
    restarts = bench.board("restarts")
    bench.partner.restart()
    await bench.wait(lambda: bench.board("restarts") > restarts, 40, "the board counting the restart")
    await bench.wait(lambda: not bench.link_up(), 40, "link down after the restart")
    await bench.wait(bench.link_up, 400, "link back after the restart")
    frames = random_frames(rng, 2)
    received, _ = await bench.to_partner(frames, 80)
    check_at_partner(frames, received)
    check_at_board(frames, await bench.from_partner(frames, 80))

    if "results" in p:
        with open(p["results"], "w") as f:
            json.dump(results, f)
