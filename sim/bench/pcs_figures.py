"""The SVEC's Ethernet figures, measured on the generated Verilog (:mod:`sim.tb.sfp_link`: the MAC,
our PCS, the GTP lane's model) against the independent link partner
(:class:`sim.models.pcs_partner.Partner`), with the partner 100 ppm fast and the core 100 ppm
slow, then the other way round: frames lost, the time to link up, throughput each way, the
time to link back after a comma slip. The run is :mod:`sim.tb.sfp_link_tb` with more frames
than its test's.

``python -m sim.bench.pcs_figures`` prints them.
"""

import json

from sim.harness import cocotb_run
from sim.harness.paths import build_dir
from sim.tb.sfp_link import BUILD_ARGS, LINK_TIMER, SOURCES, TOPLEVEL, SfpLink, plusargs

__all__ = ["link_run", "run"]

SOURCE = ("gateware: sim.tb.sfp_link_tb on the generated Verilog of the MAC, the PCS and the GTP wrapper "
          "(GTPA1_DUAL model) against sim.models.pcs_partner, Verilator")


def link_run(ppm, *, frames, offset, errors=4):
    """One run of the testbench with the partner ``ppm`` fast and the core ``ppm`` slow; its results."""
    out = build_dir("bench") / f"pcs_link_{ppm:+d}.json"
    out.unlink(missing_ok=True)
    cocotb_run.run(cocotb_run.converted(SfpLink, TOPLEVEL, "default"), toplevel=TOPLEVEL,
                   module="sim.tb.sfp_link_tb", key="default", extra_sources=SOURCES, build_args=BUILD_ARGS,
                   params={"offset": offset, "seed": offset, "frames": frames, "errors": errors, "results": str(out)},
                   plusargs=plusargs(partner_ppm=ppm, core_ppm=-ppm))
    return json.loads(out.read_text())


def run(frames=200):
    runs = [link_run(100, frames=frames, offset=3), link_run(-100, frames=frames, offset=8)]
    sent = 2 * frames * len(runs)
    return {
        "pcs.frames_lost_at_100ppm": (sum(r["tx_lost"] + r["rx_lost"] for r in runs), f"of {sent} frames", SOURCE),
        "pcs.link_up_us": (max(r["link_up_us"] for r in runs), "us", SOURCE + f"; link timer {LINK_TIMER} cycles"),
        "pcs.relink_after_slip_us": (max(r["relink_us"] for r in runs), "us",
                                     SOURCE + f"; link timer {LINK_TIMER} cycles"),
        "pcs.throughput_mbps": (min(min(r["tx_bytes"] / r["tx_us"], r["rx_bytes"] / r["rx_us"]) for r in runs) * 8,
                                "Mb/s", SOURCE + "; frame bytes with FCS, back to back, slower direction"),
        "pcs.bit_error_frames_counted": (sum(r["bad_frames"] for r in runs), f"of {sum(r['bit_errors'] for r in runs)}",
                                         SOURCE),
    }


if __name__ == "__main__":
    for name, (value, unit, _) in run().items():
        print(f"{name:36} {value:10.1f} {unit}")
