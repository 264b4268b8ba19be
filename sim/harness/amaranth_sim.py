"""Running Amaranth components in the Amaranth simulator.

``simulate(dut, testbenches, clocks=...)`` sets up one clock per domain, runs the async
testbenches and writes a VCD plus a GTKWave save file named after the test under
``build/waves/``. ``stream_put``/``stream_get`` move one payload through a
:mod:`amaranth.lib.stream` interface with the stream rules: valid never waits for ready, the
payload is held until the transfer.
"""

import os
import random

from amaranth.lib import wiring
from amaranth.sim import Simulator

from .paths import build_dir, slug

__all__ = ["simulate", "stream_put", "stream_get", "stream_collect", "stream_feed", "port_traces"]


def port_traces(component):
    """Every port of a component, for the VCD and the save file."""
    return [value for _path, _member, value in component.signature.flatten(component)]


def simulate(dut, testbenches, *, name, clocks=None, processes=(), deadline=None, waves=None, traces=()):
    """Simulate ``dut``.

    Parameters
    ----------
    dut : Elaboratable
    testbenches : list of async functions ``f(ctx)``; the simulation ends when all return.
    name : str
        Base name of the VCD and GTKWave files (a test's node id).
    clocks : dict
        Domain name to frequency in Hz; default ``{"sync": 125e6}``.
    deadline : float, optional
        Simulated seconds after which the run fails (a hung testbench).
    waves : bool, optional
        Write waves; default on unless the environment sets ``WAVES=0``.
    """
    clocks = {"sync": 125e6} if clocks is None else clocks
    sim = Simulator(dut)
    for domain, freq in clocks.items():
        sim.add_clock(1 / freq, domain=domain)
    for tb in testbenches:
        sim.add_testbench(tb)
    for proc in processes:
        sim.add_process(proc)
    if waves is None:
        waves = os.environ.get("WAVES", "1") != "0"

    if deadline is not None:
        async def watchdog(ctx):
            # a background process: it does not keep the simulation alive, it only ends a hung one
            await ctx.delay(deadline)
            raise AssertionError(f"simulation of {name} did not finish within {deadline} s")
        sim.add_process(watchdog)

    def run():
        sim.run()

    if waves:
        wave_dir = build_dir("waves")
        base = wave_dir / slug(name)
        all_traces = list(traces)
        if not all_traces and isinstance(dut, wiring.Component):
            all_traces = port_traces(dut)
        with sim.write_vcd(f"{base}.vcd", f"{base}.gtkw", traces=all_traces):
            run()
    else:
        run()
    return sim


async def stream_put(ctx, stream, payload):
    """Offer ``payload`` on a stream the testbench drives, and wait for the transfer."""
    ctx.set(stream.payload, payload)
    ctx.set(stream.valid, 1)
    await ctx.tick().until(stream.ready)
    ctx.set(stream.valid, 0)


async def stream_get(ctx, stream):
    """Accept one payload from a stream the testbench consumes."""
    ctx.set(stream.ready, 1)
    payload, = await ctx.tick().sample(stream.payload).until(stream.valid)
    ctx.set(stream.ready, 0)
    return payload


async def stream_feed(ctx, stream, payloads, *, idle=0.0, rng=None):
    """Send every payload in turn; with ``idle`` > 0, hold valid low for random cycles between."""
    rng = rng or random.Random(0)
    for payload in payloads:
        while idle and rng.random() < idle:
            await ctx.tick()
        await stream_put(ctx, stream, payload)


async def stream_collect(ctx, stream, count, *, stall=0.0, rng=None, convert=None):
    """Receive ``count`` payloads; with ``stall`` > 0, hold ready low on random cycles
    (backpressure). ``convert`` turns each sampled payload into a plain value before it is kept."""
    rng = rng or random.Random(1)
    out = []
    while len(out) < count:
        ready = not (stall and rng.random() < stall)
        ctx.set(stream.ready, ready)
        _clk, _rst, valid, payload = await ctx.tick().sample(stream.valid, stream.payload)
        if valid and ready:
            out.append(convert(payload) if convert else payload)
    ctx.set(stream.ready, 0)
    return out
