"""cocotb benchmark run of the whole Ethernet side (:class:`gateware.protocol.port.EthernetPort`) on
its generated Verilog: two XGA images in image records as large as the MTU (parameter ``mtu``)
sent back to back at the minimum gap on the GMII receive pins, then the first record of a third;
``sync`` at 125 MHz shifted 0.7 ns from the PHY clock, the pixel consumer always ready. Writes
its figures as JSON to the ``out`` parameter.

Run by the benchmark (:func:`sim.bench.net_figures.port_at_line_rate`, ``make bench``), by no pytest
test: the Ethernet side's test is ``tests/test_ethernet_verilog.py`` (:mod:`sim.tb.ethernet_tb`).

Payload rate: the pixels of one image over the time from the second image's first pixel handed
on to the third's: a stream's period, the line's time for every record of a whole image
(preamble, FCS and gap included, the last short record too). It is taken between the second and
the third image, not from the first, because each image's start waits behind the one before it
in the same way (its last record completes a row split across two records, and that row goes
out whole before the record's own: a drain the first image, with nothing ahead of it, does
not see).

Commit latency: for each record that starts a row, the ``sync`` rising edges from the one after
the receive MAC samples the record's last FCS byte (the ``gmii_rx`` edge after the source drives
it) up to and including the edge on which the record's first pixel is taken from ``pixels``. That
first transfer is the earliest effect of the record outside the block and the moment its data
starts flowing on: the stack holds the frame until its FCS verdict, so nothing of it leaves before.
The first record's (``latency_first``) is the pipeline's own: nothing is ahead of it. A later
record that starts a row may wait behind the rows before it (``latency_max``): a row split across
the two records before it goes on only once its last piece has come.
"""

import json
import math

import cocotb
import numpy as np

from host import codec
from sim.harness.cocotb_run import params
from sim.models import frames
from sim.tb.ethernet_tb import GMII_PS, A, Bench, gmii
from spec import records


@cocotb.test()
async def line_rate(dut):
    p = params()
    sync_ps = p["sync_ps"]
    bench = await Bench.start(dut, sync_ps=sync_ps, sink=False)
    dmd = bench.dmd
    limit = records.record_limit(p["mtu"])
    picture = np.random.default_rng(8).integers(0, 256, (dmd.rows, dmd.columns), dtype=np.uint8)
    encoded = codec.image_records(picture, 1, limit=limit)
    n = len(encoded)
    second = codec.image_records(picture, 2, limit=limit, sequence=n)
    following = codec.image_records(picture, 3, limit=limit, sequence=2 * n)[0]
    fcs_sampled = []
    gmii_frames = [gmii(frames.udp(A, r)) for r in encoded + second + [following]]
    for frame in gmii_frames:
        frame.tx_complete = lambda sent: fcs_sampled.append(sent.sim_time_end + GMII_PS)
    await bench.send(gmii_frames, timeout_ms=200)
    await bench.settle()

    got = bench.counters()
    delivered = bench.rows()
    pixels = codec.pixels_per_record(limit)
    arrived = set(delivered)

    def rows_of(i):
        """The rows record ``i`` carries a piece of (the last one: the third image's row 0)."""
        image, j = divmod(i, n)
        if image == 2:
            return [(3, 0)]
        first, end = j * pixels, min((j + 1) * pixels, picture.size)
        return [(image + 1, row) for row in range(first // dmd.columns, -(-end // dmd.columns))]

    # a record is intact when every row it carries a piece of arrived whole (rows are handed on
    # whole: a lost record loses the rows it touches)
    intact = sum(all((frame, row, picture[row].tobytes()) in arrived for frame, row in rows_of(i))
                 for i in range(len(gmii_frames)))
    row_start = {(frame, row): t for (frame, row, _data), t in zip(delivered, bench.row_starts, strict=True)}
    # the records that start a row (their first pixel is the row's), and when that pixel left
    starting = {i: rows_of(i)[0] for i in range(len(gmii_frames)) if i % n * pixels % dmd.columns == 0}
    latency = {i: math.ceil((row_start[row] - fcs_sampled[i]) / sync_ps) for i, row in starting.items()
               if row in row_start}
    latencies = list(latency.values())
    span = row_start.get((3, 0), 0) - row_start.get((2, 0), 0)
    with open(p["out"], "w") as f:
        json.dump({
            "records": len(gmii_frames), "intact": intact, "frame_bytes": len(gmii_frames[0].data) - 8,
            "rx_dropped": got["rx_dropped"], "drop_overflow": got["net"]["drop_overflow"],
            "records_image": got["app"]["records_image"], "mac_good": got["mac"]["good"],
            "rows_incomplete": got["app"]["rows_incomplete"],
            "payload_bytes": picture.size, "line_bytes": span / GMII_PS,
            "latency_first": latency.get(0), "latency_min": min(latencies), "latency_max": max(latencies),
            "header_bytes": records.IMAGE_HEADER, "pixels_per_record": pixels,
        }, f)
