"""The receive path (MAC + crossing into ``sync``) in the Amaranth simulator: nothing lost when the
consumer keeps up, whole frames dropped and counted when it does not, never a partial good one."""

import random

from gateware.mac.path import ReceivePath
from sim.harness.amaranth_sim import simulate
from sim.models import mac_model as mac


def run_path(symbols, name, *, stall=0.0, depth=16384, max_frame=9018, sync_hz=125e6):
    """Drive ``symbols`` on the pins while a ``sync`` consumer takes the frames, holding ready low
    with probability ``stall``. Returns the frames received (bytes, bad), the verdict counters and
    the drop count, both read in ``sync``."""
    dut = ReceivePath(depth=depth, max_frame=max_frame)
    out = {"beats": [], "done": False}
    rng = random.Random(21)

    async def drive(ctx):
        for d, dv, er in symbols:
            ctx.set(dut.gmii, {"d": d, "dv": dv, "er": er})
            await ctx.tick("gmii_rx")
        ctx.set(dut.gmii, {"d": 0, "dv": 0, "er": 0})
        out["done"] = True

    async def consume(ctx):
        quiet = 0
        while quiet < 64:
            ready = not (stall and rng.random() < stall)
            ctx.set(dut.frames.ready, ready)
            _, _, valid, beat = await ctx.tick().sample(dut.frames.valid, dut.frames.payload)
            if valid and ready:
                out["beats"].append((int(beat.data), int(beat.last), int(beat.user)))
                quiet = 0
            elif out["done"]:
                quiet += 1
        out["counters"] = {v: ctx.get(dut.counters[v]) for v in mac.VERDICTS}
        out["dropped"] = ctx.get(dut.dropped)

    simulate(dut, [drive, consume], name=f"mac_{name}", clocks={"gmii_rx": 125e6, "sync": sync_hz},
             deadline=5e-2)
    return mac.split_frames(out["beats"]), out["counters"], out["dropped"]


def back_to_back(frames, gap=12):
    symbols = []
    for f in frames:
        symbols += mac.wire(f) + mac.idle(gap)
    return symbols


def test_line_rate_nothing_lost(test_name):
    """Back-to-back frames at the minimum gap, a consumer that keeps up at 125 MHz."""
    rng = mac.seeded(30)
    frames = [mac.frame_of_length(n, rng) for n in mac.random_sizes(rng, 8)]
    got, counters, dropped = run_path(back_to_back(frames), test_name)
    assert got == [(f[:-4], False) for f in frames]
    assert dropped == 0 and counters["good"] == len(frames)


def check_drops(frames, got, dropped):
    """Every frame passed as good is a sent frame, in order, whole; the rest were counted."""
    sent = [f[:-4] for f in frames]
    good = [f for f, bad in got if not bad]
    it = iter(sent)
    assert all(any(g == s for s in it) for g in good), "a good frame out of order or altered"
    assert len(good) + dropped == len(sent)
    return good


def test_slow_consumer_drops_whole_frames(test_name):
    """A consumer ready a third of the time: frames are dropped whole at their start (the FIFO
    holds a whole frame), so none arrives cut, and each drop is counted."""
    rng = mac.seeded(31)
    frames = [mac.frame_of_length(rng.randint(64, 600), rng) for _ in range(20)]
    got, counters, dropped = run_path(back_to_back(frames), test_name, stall=0.67, depth=1024,
                                      max_frame=1000)
    good = check_drops(frames, got, dropped)
    assert dropped > 0 and len(good) > 0
    assert all(not bad for _, bad in got), "the FIFO holds a whole frame: nothing is cut"
    assert counters["good"] == len(frames)


def test_fifo_shorter_than_frames_cuts_and_flags(test_name):
    """With a FIFO shorter than the frames and a slow consumer, a frame that runs out of room
    mid-way leaves short and flagged bad, never as a good frame."""
    rng = mac.seeded(32)
    frames = [mac.frame_of_length(500, rng) for _ in range(8)]
    got, _counters, dropped = run_path(back_to_back(frames), test_name, stall=0.8, depth=256)
    good = check_drops(frames, got, dropped)
    cut = [f for f, bad in got if bad]
    assert cut, "expected frames cut for lack of room"
    assert all(any(s[:-4].startswith(f) for s in frames) and len(f) < 496 for f in cut)
    assert all(len(g) == 496 for g in good)
