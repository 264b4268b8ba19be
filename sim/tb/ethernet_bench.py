"""cocotb benchmark run of the whole Ethernet side (:class:`gateware.protocol.port.EthernetPort`) on
its generated Verilog: XGA image records in jumbo frames sent back to back at the minimum gap on
the GMII receive pins, ``sync`` at 125 MHz shifted 0.7 ns from the PHY clock, the pixel consumer
always ready. Writes its figures as JSON to the ``out`` parameter.

Commit latency: for each record, the ``sync`` rising edges from the one after the receive MAC
samples the record's last FCS byte (the ``gmii_rx`` edge after the source drives it) up to and
including the edge on which the record's first pixel is taken from ``pixels``. That first
transfer is the earliest effect of the record outside the block and the moment its data starts
flowing on: the stack holds the frame until its FCS verdict, so nothing of it leaves before.
"""

import json
import math

import cocotb
import numpy as np

from host import codec
from sim.harness.cocotb_run import params
from sim.models import frames
from sim.tb.ethernet import GMII_PS, A, Bench, gmii
from spec import records


@cocotb.test()
async def line_rate(dut):
    p = params()
    sync_ps = p["sync_ps"]
    bench = await Bench.start(dut, sync_ps=sync_ps, sink=False)
    dmd = bench.dmd
    rows = codec.rows_per_record(dmd.columns)
    picture = np.random.default_rng(8).integers(0, 256, (p["records"] * rows, dmd.columns), dtype=np.uint8)
    encoded = codec.image_records(picture, 1)
    fcs_sampled = []
    gmii_frames = [gmii(frames.udp(A, r)) for r in encoded]
    for frame in gmii_frames:
        frame.tx_complete = lambda sent: fcs_sampled.append(sent.sim_time_end + GMII_PS)
    await bench.send(gmii_frames, timeout_ms=100)
    await bench.settle()

    got = bench.counters()
    delivered = bench.rows()
    intact = sum(1 for i in range(len(encoded))
                 if delivered[i * rows:(i + 1) * rows] == [(1, r, picture[r].tobytes())
                                                            for r in range(i * rows, (i + 1) * rows)])
    # Pair each record's first pixel with its frame by row number, so a lost record shifts nothing.
    row_start = {row: t for (_frame, row, _data), t in zip(delivered, bench.row_starts, strict=True)}
    starts = [row_start[i * rows] for i in range(len(encoded)) if i * rows in row_start]
    latencies = [math.ceil((row_start[i * rows] - fcs) / sync_ps) for i, fcs in enumerate(fcs_sampled)
                 if i * rows in row_start]
    payload = (len(encoded) - 1) * rows * dmd.columns
    with open(p["out"], "w") as f:
        json.dump({
            "records": len(encoded), "intact": intact, "frame_bytes": len(gmii_frames[0].data) - 8,
            "rx_dropped": got["rx_dropped"], "drop_overflow": got["net"]["drop_overflow"],
            "records_image": got["app"]["records_image"], "mac_good": got["mac"]["good"],
            "payload_bytes": payload, "line_bytes": (starts[-1] - starts[0]) / GMII_PS,
            "latency_min": min(latencies), "latency_max": max(latencies),
            "header_bytes": records.image_record_length(rows, dmd.columns) - rows * dmd.columns,
        }, f)
