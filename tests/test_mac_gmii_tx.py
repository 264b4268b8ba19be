"""The GMII transmit MAC and the transmit path in the Amaranth simulator, against zlib and scapy."""

import random

from gateware.mac.gmii_tx import Transmitter
from gateware.mac.path import TransmitPath
from sim.harness.amaranth_sim import simulate, stream_put
from sim.models import mac_model as mac


def beats(frame, *, abort=False):
    return [{"data": b, "last": int(i == len(frame) - 1), "user": int(abort and i == len(frame) - 1)}
            for i, b in enumerate(frame)]


def on_wire(frame):
    """What the MAC must send for ``frame``: padded to 60 bytes, then the FCS."""
    return mac.with_fcs(frame + bytes(max(0, 60 - len(frame))))


async def record(ctx, pins, cycles, domain="sync"):
    symbols = []
    for _ in range(cycles):
        _, _, value = await ctx.tick(domain).sample(pins)
        symbols.append((int(value.d), int(value.en), int(value.er)))
    return symbols


def run_transmitter(frames, name, *, pause_in=None, idle=0.0):
    """Send ``frames`` (list of (bytes, abort)); ``pause_in`` = (frame index, byte index)
    withholds the input there for a few cycles. Returns the pin symbols and the underrun count."""
    dut = Transmitter(domain="sync")
    total = sum(len(f) + 40 for f, _ in frames) + 200
    out = {}
    rng = random.Random(3)

    async def feed(ctx):
        for n, (frame, abort) in enumerate(frames):
            for i, beat in enumerate(beats(frame, abort=abort)):
                if pause_in == (n, i):
                    await ctx.tick().repeat(3)
                while idle and rng.random() < idle:
                    await ctx.tick()
                await stream_put(ctx, dut.frames, beat)

    async def watch(ctx):
        out["symbols"] = await record(ctx, dut.gmii, total)
        out["underruns"] = ctx.get(dut.underruns)

    simulate(dut, [feed, watch], name=f"mac_{name}", deadline=1e-2)
    return out["symbols"], out["underruns"]


def test_frames_padding_fcs_and_gap(test_name):
    """Frames of 1 to 1500 bytes (scapy-built above the UDP header), sent back to back."""
    rng = mac.seeded(10)
    frames = [bytes([0xAA]), bytes(range(30)), mac.udp_frame(b"")]
    frames += [mac.frame_of_length(n, rng)[:-4] for n in (64, 65, 200, 1518)]
    symbols, underruns = run_transmitter([(f, False) for f in frames], test_name)
    sent = mac.wire_frames(symbols)
    assert [s[0] for s in sent] == [on_wire(f) for f in frames]
    assert not any(s[2] for s in sent) and underruns == 0
    # The first frame goes at once; the others follow at exactly the minimum gap.
    assert [s[1] for s in sent[1:]] == [12] * (len(frames) - 1)


def test_abort_sends_bad_fcs(test_name):
    rng = mac.seeded(11)
    good, doomed = mac.frame_of_length(100, rng)[:-4], mac.frame_of_length(100, rng)[:-4]
    symbols, _ = run_transmitter([(good, False), (doomed, True), (good, False)], test_name)
    sent = [s[0] for s in mac.wire_frames(symbols)]
    assert sent[0] == sent[2] == on_wire(good)
    assert sent[1][:-4] == doomed and sent[1] != on_wire(doomed)
    assert mac.receive(mac.wire(sent[1]))[0].verdict == "bad_fcs"


def test_underrun_poisons_frame(test_name):
    """Input that runs dry mid-frame: tx_er on the wire, the frame cut, counted, next one fine."""
    rng = mac.seeded(12)
    first, second = mac.frame_of_length(120, rng)[:-4], mac.frame_of_length(80, rng)[:-4]
    symbols, underruns = run_transmitter([(first, False), (second, False)], test_name, pause_in=(0, 50))
    sent = mac.wire_frames(symbols)
    assert underruns == 1 and len(sent) == 2
    assert sent[0][2] and mac.receive(mac.wire(sent[0][0], errors=[8 + 50]))[0].verdict == "rx_er"
    assert sent[1][0] == on_wire(second) and not sent[1][2]


def test_transmit_path_never_underruns(test_name):
    """Through the crossing from a 100 MHz ``sync`` with an irregular producer: whole frames are
    buffered before they start, so none underruns and frames queued behind leave at the gap."""
    rng = mac.seeded(13)
    frames = [mac.frame_of_length(n, rng)[:-4] for n in (64, 300, 1518, 70, 700)]
    dut = TransmitPath(depth=2048)
    total = sum(len(f) + 40 for f in frames) * 2 + 400
    out = {}
    feed_rng = random.Random(4)

    async def feed(ctx):
        for frame in frames:
            for beat in beats(frame):
                while feed_rng.random() < 0.3:
                    await ctx.tick()
                await stream_put(ctx, dut.frames, beat)

    async def watch(ctx):
        out["symbols"] = await record(ctx, dut.gmii, total, domain="gmii_tx")

    async def counters(ctx):
        await ctx.tick().repeat(total)
        out["underruns"] = ctx.get(dut.underruns)

    simulate(dut, [feed, watch, counters], name=f"mac_{test_name}", clocks={"sync": 100e6, "gmii_tx": 125e6},
             deadline=1e-2)
    sent = mac.wire_frames(out["symbols"])
    assert [s[0] for s in sent] == [on_wire(f) for f in frames]
    assert not any(s[2] for s in sent) and out["underruns"] == 0
    assert all(s[1] >= 12 for s in sent[1:])
