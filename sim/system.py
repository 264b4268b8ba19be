"""``make sim``: the most complete simulation of the projector there is, on the default scene.

Today that is the bit-plane serialiser's generated Verilog under Verilator, fed the default
scene (1024x768, 8 bits, a target moving over a structured background) and checked plane by
plane against numpy. When the system top exists this runs it instead: frames over GMII, a
trigger, the DMD and camera models.
"""

import json
import os
import time

from gateware.bitplane import Serialiser
from gateware.dlpc410.facts import DMDS
from sim.harness import cocotb_run
from sim.harness.paths import build_dir

__all__ = ["main"]


def main(frames=None):
    frames = frames or 3
    dmd, lanes = "dlp7000", 8
    print("make sim: the system top does not exist yet; running the most complete simulation there "
          "is: the bit-plane serialiser's Verilog (Verilator) on the default scene.")
    print(f"scene: {frames} frames of {DMDS[dmd].columns}x{DMDS[dmd].rows} 8-bit pixels, {lanes} pixels per cycle")
    os.environ.setdefault("WAVES", "1")
    out = build_dir("sim")
    report = out / "scene_serialiser.json"
    t0 = time.monotonic()
    build = cocotb_run.run(Serialiser(DMDS[dmd], lanes=lanes), toplevel="bitplane_serialiser",
                           module="sim.tb.scene_serialiser", key=f"{dmd}-{lanes}-scene",
                           params={"dmd": dmd, "lanes": lanes, "frames": frames, "report": str(report)})
    result = json.loads(report.read_text())
    cycles = sum(f["cycles"] for f in result["frames"])
    pixels = sum(f["pixels"] for f in result["frames"])
    print()
    print(f"frames checked against numpy: {len(result['frames'])} (every plane of every frame equal)")
    print(f"serialiser throughput: {pixels / cycles:.3f} pixel/cycle "
          f"({pixels / cycles * 125e6 / 1e6:.0f} Mpixel/s at sync = 125 MHz)")
    print(f"simulation speed: {cycles / result['wall_s']:.0f} simulated cycles per wall second")
    print(f"wall time: {time.monotonic() - t0:.1f} s (including the Verilator build)")
    vcd = build / "dump.vcd"
    if vcd.exists():
        gtkw = write_save_file(vcd)
        print(f"waves: {vcd}\n  GTKWave save file: {gtkw}")
    return 0


def write_save_file(vcd):
    """A GTKWave save file that groups the serialiser's ports."""
    groups = {
        "pixels in": ["pixels__valid", "pixels__ready", "pixels__payload[63:0]"],
        "words out": ["words__valid", "words__ready", "words__payload[63:0]"],
        "row flags": ["rows__valid", "rows__ready", "rows__payload"],
    }
    lines = [f'[dumpfile] "{vcd}"', "[timestart] 0", "@28", "TOP.bitplane_serialiser.clk",
             "TOP.bitplane_serialiser.rst"]
    for group, signals in groups.items():
        lines.append(f"-{group}")
        for sig in signals:
            lines.append(f"TOP.bitplane_serialiser.{sig}")
    path = vcd.with_suffix(".gtkw")
    path.write_text("\n".join(lines) + "\n")
    return path
