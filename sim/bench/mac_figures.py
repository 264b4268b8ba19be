"""GMII MAC figures: receive latency (Amaranth simulator, exact), and drops and throughput at line
rate through the receive MAC and its crossing (the generated Verilog under Verilator)."""

import json

from gateware.mac.axis import AxisReceiver
from gateware.mac.gmii_rx import Receiver
from gateware.mac.path import ReceivePath
from sim.harness import cocotb_run
from sim.harness.amaranth_sim import simulate
from sim.harness.paths import build_dir
from sim.models import mac_model as mac

__all__ = ["rx_latency", "line_rate", "run"]


def rx_latency(path=False, length=64):
    """``gmii_rx`` cycles from the last FCS byte on the pins to the last byte, with its verdict,
    leaving the receive MAC; with ``path``, leaving the receive path in ``sync`` (both clocks at
    125 MHz, in phase, the consumer always ready)."""
    dut = ReceivePath() if path else Receiver()
    out = dut.frames
    symbols = mac.wire(mac.frame_of_length(length, mac.seeded(0))) + mac.idle(32)
    last_fcs = len(symbols) - 32 - 1
    result = {}

    async def bench(ctx):
        if path:
            ctx.set(out.ready, 1)
        for cycle, (d, dv, er) in enumerate(symbols):
            ctx.set(dut.gmii, {"d": d, "dv": dv, "er": er})
            await ctx.delay(1e-12)
            if ctx.get(out.valid) and ctx.get(out.payload.last) and "cycles" not in result:
                result["cycles"] = cycle - last_fcs
            await ctx.tick("gmii_rx")

    simulate(dut, [bench], name="bench_mac_rx_latency", clocks={"gmii_rx": 125e6, "sync": 125e6} if path
             else {"gmii_rx": 125e6}, waves=False, deadline=1e-3)
    return result["cycles"]


def line_rate(frames=290, jumbos=10, throughput_frames=6):
    """Run :mod:`sim.tb.mac_rx_line_rate_tb` on the receive path's Verilog; return its figures."""
    out = build_dir("bench") / "mac_rx_line_rate.json"
    out.unlink(missing_ok=True)
    cocotb_run.run(AxisReceiver(), toplevel="mac_axis_rx", module="sim.tb.mac_rx_line_rate_tb", key="default",
                   params={"out": str(out), "frames": frames, "jumbos": jumbos,
                           "throughput_frames": throughput_frames})
    return json.loads(out.read_text())


def run():
    """The figures. ``eth.mac_payload_fraction_of_line_rate`` counts the bytes the MAC hands on
    (destination MAC to payload) per byte time of the line, with 9,018-byte frames at the minimum
    gap: at most 9,014 / (9,018 + 8 + 12) = 0.99734, the preamble, FCS and gap being the rest."""
    latency = rx_latency()
    path_latency = rx_latency(path=True)
    rate = line_rate()
    fraction = rate["throughput_bytes"] / rate["throughput_line_bytes"]
    line = "gateware: receive path's Verilog (AxisReceiver) under Verilator, sim.tb.mac_rx_line_rate_tb at line rate"
    return {
        "eth.mac_rx_latency_cycles": (latency, "cycle", "gateware: receive MAC, Amaranth simulator, a 64-byte frame"),
        "eth.mac_rx_to_sync_latency_cycles": (path_latency, "cycle",
                                              "gateware: receive path, Amaranth simulator, a 64-byte frame"),
        "eth.mac_drops_at_line_rate": (rate["frames"] - rate["intact"], "frame", line),
        "eth.mac_payload_fraction_of_line_rate": (fraction, "1", line),
    }


if __name__ == "__main__":
    for name, (value, unit, *_source) in run().items():
        print(f"{name:45} {value:>12.6g} {unit}")
