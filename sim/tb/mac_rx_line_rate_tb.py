"""cocotb benchmark run of the receive path's Verilog: hundreds of frames, jumbo ones among them,
at line rate with the minimum gap, into a ``sync`` consumer that is always ready but clocked
250 ppm slower than the PHY (beyond the worst crystal pairing). Writes its figures as JSON to the
``out`` parameter.

Run by the benchmark (:func:`sim.bench.mac_figures.line_rate`, ``make bench``), by no pytest test:
the receive MAC's test is ``tests/test_mac_rx_verilog.py`` (:mod:`sim.tb.mac_rx_tb`)."""

import json

import cocotb
from cocotb.triggers import with_timeout

from sim.harness.cocotb_run import params
from sim.models import mac_model as mac
from sim.tb.mac_rx_tb import CLOCK_NS, Bench

#: The consumer's clock, 250 ppm slower than the PHY's 8 ns (two ±100 ppm crystals at worst give 200).
SYNC_PS = 8002


@cocotb.test()
async def line_rate(dut):
    p = params()
    rng = mac.seeded(70)
    bench = await Bench.start(dut, sync_ps=SYNC_PS)

    # Drops: a few hundred frames of every size, jumbo ones shuffled in.
    sizes = mac.random_sizes(rng, p["frames"], jumbo=[9018] * p["jumbos"])
    rng.shuffle(sizes)
    frames = [mac.frame_of_length(n, rng) for n in sizes]
    await with_timeout(bench.send(frames), 100, "ms")
    await bench.settle()
    got = bench.received()
    # Frames that came out good and identical, matched in order (a lost frame is skipped over).
    intact, pending = 0, iter(frames)
    for f, bad in got:
        if not bad and any(f == sent[:-4] for sent in pending):
            intact += 1
    _, dropped = bench.counters()

    # Throughput: jumbo frames back to back; in steady state, bytes out per line byte time
    # between the ends of the first and the last frame leaving the MAC.
    jumbos = [mac.frame_of_length(9018, rng) for _ in range(p["throughput_frames"])]
    await with_timeout(bench.send(jumbos), 100, "ms")
    await bench.settle()
    out = []
    while not bench.sink.empty():
        out.append(bench.sink.recv_nowait())
    assert [bytes(f.tdata) for f in out] == [j[:-4] for j in jumbos]
    delivered = sum(len(f.tdata) for f in out[1:])
    line_bytes = (out[-1].sim_time_end - out[0].sim_time_end) / (CLOCK_NS * 1000)

    with open(p["out"], "w") as f:
        json.dump({
            "frames": len(frames), "intact": intact, "dropped_counter": dropped,
            "throughput_bytes": delivered, "throughput_line_bytes": line_bytes,
            "throughput_frames": len(out) - 1,
        }, f)
