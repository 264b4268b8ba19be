"""Ethernet ingest figures.

End to end (:func:`port_at_line_rate`): the whole Ethernet side (:class:`gateware.protocol.port.
EthernetPort`, GMII MAC + stack + protocol) as generated Verilog under Verilator and cocotb,
XGA image records in jumbo frames back to back at the minimum gap on the GMII receive pins
(:mod:`sim.tb.ethernet_bench`). This gives the payload rate, the XGA image rate, the drops and
the commit latency.

Stack alone (:func:`endpoint_at_line_rate`, Amaranth simulator): the endpoint fed at GMII
timing: one byte per cycle, and between frames the 8 preamble/SFD, 4 FCS and 12 inter-frame gap
cycles the line spends on them (24 idle cycles). The consumer of the pixels never stalls.
"""

import json

import numpy as np

from host import codec
from sim.harness import cocotb_run
from sim.harness.paths import build_dir
from sim.models import frames
from sim.tb import endpoint_sim
from spec.facts import DMDS

#: Line cycles per frame that carry no frame byte: preamble + SFD, FCS, inter-frame gap.
GMII_OVERHEAD = 8 + 4 + 12
LINE_RATE = 125e6  # bytes per second on gigabit GMII


def endpoint_at_line_rate(records_count=6, dmd="dlp7000"):
    geometry = DMDS[dmd]
    rows = codec.rows_per_record(geometry.columns)
    image = np.random.default_rng(0).integers(0, 256, (rows * records_count, geometry.columns),
                                              dtype=np.uint8)
    encoded = codec.image_records(image, 1)
    a = frames.Addresses()
    sequence = [(frames.udp(a, record), False) for record in encoded]
    out = endpoint_sim.run(sequence, name="bench_net_line_rate", dmd=geometry, gap=(GMII_OVERHEAD,) * 2,
                         waves=False, settle=50)
    assert out["app"]["payload_bytes"] == len(out["pixels"]) == image.size
    # Steady state: the records leave one after another, so the payload rate is the payload of
    # all records but the first over the cycles from the first record's first pixel to the last
    # record's; at line rate that is the line time of those frames, bytes plus GMII overhead.
    starts = out["first_pixel"][::rows]
    cycles = starts[-1] - starts[0]
    payload = (len(encoded) - 1) * rows * geometry.columns
    drops = sum(v for k, v in out["net"].items() if k.startswith("drop_")) \
        + sum(v for k, v in out["app"].items() if k.startswith("drop_app"))
    drops += len(encoded) - out["app"]["records_image"]
    return {
        "payload_fraction": payload / cycles,
        "drops": drops,
        "commit_latency": out["first_pixel"][0] - out["last_in"][0],
        "rx_stalls": out["rx_stalls"],
        "frame_bytes": len(sequence[0][0]),
    }


def port_at_line_rate(records_count=None, sync_ps=8000):
    """Run :mod:`sim.tb.ethernet_bench` on the Ethernet port's Verilog; ``records_count`` XGA
    records (default: one whole 1024x768 image). Returns its figures."""
    from sim.tb.ethernet_pins import TOPLEVEL, build
    xga = DMDS["dlp7000"]
    records_count = records_count or xga.rows // codec.rows_per_record(xga.columns)
    out = build_dir("bench") / "ethernet_port_line_rate.json"
    out.unlink(missing_ok=True)
    cocotb_run.run(build("dlp7000"), toplevel=TOPLEVEL, module="sim.tb.ethernet_bench", key="dlp7000",
                   params={"dmd": "dlp7000", "out": str(out), "records": records_count, "sync_ps": sync_ps})
    return json.loads(out.read_text())


def run():
    """The figures. ``eth.commit_latency_cycles`` is in ``sync`` cycles at 125 MHz: see
    :mod:`sim.tb.ethernet_bench` for the two events it spans (the largest over all records)."""
    port = port_at_line_rate()
    fraction = port["payload_bytes"] / port["line_bytes"]
    stack = endpoint_at_line_rate()
    xga = DMDS["dlp7000"]
    return {
        "eth.payload_fraction_of_line_rate": (fraction, "fraction"),
        "eth.xga_frames_per_s": (fraction * LINE_RATE / (xga.columns * xga.rows), "frame/s"),
        "eth.drops_at_line_rate": (port["records"] - port["intact"], "records"),
        "eth.commit_latency_cycles": (port["latency_max"], "cycles"),
        "eth.line_rate_records": (port["records"], "records"),
        "eth.stack_commit_latency_cycles": (stack["commit_latency"], "cycles"),
        "eth.rx_stall_cycles_at_line_rate": (stack["rx_stalls"], "cycles"),
        "eth.jumbo_frame_bytes": (port["frame_bytes"], "bytes"),
    }


if __name__ == "__main__":
    for name, (value, unit) in run().items():
        print(f"{name:40} {value:.6g} {unit}")
