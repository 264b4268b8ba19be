"""The receive crossing alone in the Amaranth simulator, with a tiny FIFO so that drops and cuts
happen often: whatever the consumer does, a frame leaves good only if it is whole and unaltered,
and every frame that does not is counted."""

import random

import pytest

from gateware.mac.cdc import RxCrossing
from sim.harness.amaranth_sim import simulate
from sim.models import mac_model as mac


@pytest.mark.parametrize("sync_hz,stall", [(125e6, 0.0), (100e6, 0.5), (150e6, 0.8)])
def test_rx_crossing_whole_frames_only(sync_hz, stall, test_name):
    rng = random.Random(int(sync_hz) + int(stall * 10))
    # Frames of 1 to 40 bytes, the first byte numbering them so that any prefix names its frame.
    frames = [bytes([n]) + rng.randbytes(rng.randint(0, 39)) for n in range(150)]
    dut = RxCrossing(depth=32, room=8)
    out = {"beats": [], "done": False}

    async def write(ctx):
        for data in frames:
            for i, byte in enumerate(data):
                ctx.set(dut.i.valid, 1)
                ctx.set(dut.i.payload, {"data": byte, "last": i == len(data) - 1, "user": 0})
                await ctx.tick("gmii_rx")
            ctx.set(dut.i.valid, 0)
            await ctx.tick("gmii_rx").repeat(rng.randint(1, 3))
        out["dropped"] = ctx.get(dut.dropped)
        out["done"] = True

    async def read(ctx):
        quiet = 0
        while quiet < 32:
            ready = not (stall and rng.random() < stall)
            ctx.set(dut.o.ready, ready)
            _, _, valid, beat = await ctx.tick().sample(dut.o.valid, dut.o.payload)
            if valid and ready:
                out["beats"].append((int(beat.data), int(beat.last), int(beat.user)))
                quiet = 0
            elif out["done"]:
                quiet += 1

    simulate(dut, [write, read], name=f"mac_{test_name}", clocks={"gmii_rx": 125e6, "sync": sync_hz},
             deadline=1e-3)
    got = mac.split_frames(out["beats"])
    numbers = [data[0] for data, _ in got]
    assert numbers == sorted(set(numbers)), "frames out of order or repeated"
    for data, bad in got:
        sent = frames[data[0]]
        assert sent.startswith(data), "bytes altered"
        assert bad or data == sent, "a cut frame left as good"
    # Every frame that did not arrive whole and good was counted, and no other.
    whole = sum(1 for data, bad in got if not bad)
    assert out["dropped"] == len(frames) - whole
    if stall:
        assert any(bad for _, bad in got) and len(got) < len(frames), "expected both cuts and drops"
