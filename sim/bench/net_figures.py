"""Ethernet ingest figures.

End to end (:func:`port_at_line_rate`): the whole Ethernet side (:class:`gateware.protocol.port.
EthernetPort`, GMII MAC + stack + protocol) as generated Verilog under Verilator and cocotb, XGA
images in image records as large as the MTU, back to back at the minimum gap on the GMII receive
pins (:mod:`sim.tb.ethernet_line_rate_tb`), for an ordinary 1500-byte MTU and for jumbo frames
(9,000). This gives the payload rate (pixel bytes over the line's bytes, preamble, FCS and gap
included: an image's pixels over the time between two images' first pixels handed on), the XGA image
rate, the drops and the commit latency.

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
from spec import records
from spec.facts import DMDS

#: Line cycles per frame that carry no frame byte: preamble + SFD, FCS, inter-frame gap.
GMII_OVERHEAD = 8 + 4 + 12
LINE_RATE = 125e6  # bytes per second on gigabit GMII
MTUS = {"mtu1500": 1500, "jumbo": 9000}


def endpoint_at_line_rate(records_count=6, dmd="dlp7000", mtu=9000):
    geometry = DMDS[dmd]
    limit = records.record_limit(mtu)
    pixels = codec.pixels_per_record(limit)
    image = np.random.default_rng(0).integers(0, 256, (-(-records_count * pixels // geometry.columns),
                                                       geometry.columns), dtype=np.uint8)
    encoded = codec.image_records(image, 1, limit=limit)
    a = frames.Addresses()
    sequence = [(frames.udp(a, record), False) for record in encoded]
    out = endpoint_sim.run(sequence, name="bench_net_line_rate", dmd=geometry, gap=(GMII_OVERHEAD,) * 2,
                           waves=False, settle=50)
    assert out["app"]["payload_bytes"] == len(out["pixels"]) == image.size
    drops = sum(v for k, v in out["net"].items() if k.startswith("drop_")) \
        + sum(v for k, v in out["app"].items() if k.startswith("drop_app"))
    drops += len(encoded) - out["app"]["records_image"]
    return {
        "drops": drops,
        "commit_latency": out["first_pixel"][0] - out["last_in"][0],
        "rx_stalls": out["rx_stalls"],
        "frame_bytes": len(sequence[0][0]),
    }


def port_at_line_rate(mtu=9000, sync_ps=8000):
    """Run :mod:`sim.tb.ethernet_line_rate_tb` on the Ethernet port's Verilog with records for
    ``mtu``; returns its figures."""
    from sim.tb.ethernet_pins import TOPLEVEL, build
    out = build_dir("bench") / f"ethernet_port_line_rate_{mtu}.json"
    out.unlink(missing_ok=True)
    cocotb_run.run(build("dlp7000"), toplevel=TOPLEVEL, module="sim.tb.ethernet_line_rate_tb", key="dlp7000",
                   params={"dmd": "dlp7000", "out": str(out), "mtu": mtu, "sync_ps": sync_ps})
    return json.loads(out.read_text())


def run():
    """The figures. ``eth.commit_latency_cycles`` is in ``sync`` cycles at 125 MHz: see
    :mod:`sim.tb.ethernet_line_rate_tb` for the two events it spans (the first record's, with
    nothing ahead of it); ``eth.queued_latency_cycles_max`` the largest over the records that start
    a row, waiting behind the rows before them included. Unprefixed figures are the jumbo path's;
    ``eth.mtu1500_*`` the 1500-byte MTU's."""
    xga = DMDS["dlp7000"]
    figures = {}
    for name, mtu in MTUS.items():
        port = port_at_line_rate(mtu)
        fraction = port["payload_bytes"] / port["line_bytes"]
        prefix = "eth." if mtu == 9000 else f"eth.{name}_"
        source = (f"gateware: Ethernet port's Verilog (GMII MAC, stack, protocol) under Verilator, "
                  f"sim.tb.ethernet_line_rate_tb, MTU {mtu}, XGA image records back to back at line rate")
        figures.update({
            f"{prefix}payload_fraction_of_line_rate": (fraction, "fraction", source),
            f"{prefix}xga_frames_per_s": (fraction * LINE_RATE / (xga.columns * xga.rows), "frame/s",
                                          f"arithmetic: {prefix}payload_fraction_of_line_rate x 125 MB/s "
                                          f"over an XGA image's bytes"),
            f"{prefix}drops_at_line_rate": (port["records"] - port["intact"], "records", source),
            f"{prefix}commit_latency_cycles": (port["latency_first"], "cycles", source),
            f"{prefix}queued_latency_cycles_max": (port["latency_max"], "cycles", source),
            f"{prefix}line_rate_records": (port["records"], "records", source),
            f"{prefix}frame_bytes": (port["frame_bytes"], "bytes", source),
            f"{prefix}rows_incomplete_at_line_rate": (port["rows_incomplete"], "rows", source),
        })
    stack = endpoint_at_line_rate()
    source = "gateware: protocol endpoint, Amaranth simulator, fed at GMII timing (sim.tb.endpoint_sim)"
    figures.update({
        "eth.stack_commit_latency_cycles": (stack["commit_latency"], "cycles", source),
        "eth.rx_stall_cycles_at_line_rate": (stack["rx_stalls"], "cycles", source),
        "eth.stack_drops_at_line_rate": (stack["drops"], "records", source),
    })
    return figures


if __name__ == "__main__":
    for name, (value, unit, *_source) in run().items():
        print(f"{name:44} {value:.6g} {unit}")
