"""``make verilog``: the Spartan-6 ISE tree and each block's Verilog, linted by Verilator.

``build/spartan6/`` receives what Amaranth's Xilinx platform writes for ISE (``<top>.v``,
``<top>.ucf``, ``<top>.prj``, ``<top>.xst``, ``build_<top>.sh``) without running ISE, plus
``blocks/<block>.v`` for every block in :data:`flow.blocks.BLOCKS`; ``sync_master/`` the same
for the sync master's own build (a tiled display's main control board,
:mod:`gateware.top.sync_master`).
"""

import subprocess
from pathlib import Path

from amaranth.back import verilog as amaranth_verilog

from flow.blocks import BLOCKS

__all__ = ["emit_blocks", "emit_platform", "emit_sync_master", "lint", "main"]


def block_verilog(name):
    return amaranth_verilog.convert(BLOCKS[name](), name=name, emit_src=False, strip_internal_attrs=True)


def emit_blocks(outdir):
    outdir = Path(outdir) / "blocks"
    outdir.mkdir(parents=True, exist_ok=True)
    paths = {}
    for name in BLOCKS:
        path = outdir / f"{name}.v"
        path.write_text(block_verilog(name))
        paths[name] = path
    return paths


def platform_top():
    """The top the Spartan-6 tree is built from (the projector's, once the system exists)."""
    try:
        from gateware.top.platform import PlatformTop
        return "projector", PlatformTop()
    except ImportError:
        from gateware.top.bringup import BringupTop
        return "bringup", BringupTop()


def emit_platform(outdir):
    from gateware.platform import Board
    name, top = platform_top()
    extra = {}
    if name == "projector":
        from gateware.top.platform import UCF_EXTRA
        extra["add_constraints"] = UCF_EXTRA
    plan = Board().build(top, name=name, do_build=False, **extra)
    plan.extract(str(outdir))
    return name


def emit_sync_master(outdir):
    """The sync master's ISE tree in ``outdir``; returns its top's name."""
    from gateware.top.sync_master import SyncMasterPlatform, SyncMasterTop
    SyncMasterPlatform().build(SyncMasterTop(), name="sync_master", do_build=False).extract(str(outdir))
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


def main(outdir="build/spartan6"):
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    top = emit_platform(outdir)
    blocks = emit_blocks(outdir)
    master = emit_sync_master(outdir / "sync_master")
    for name, where in ((top, outdir), (master, outdir / "sync_master")):
        print(f"Spartan-6 ISE tree for top '{name}' in {where}/:")
        for path in sorted(where.iterdir()):
            if path.is_file():
                print(f"  {path.name}")
    print(f"block Verilog in {outdir}/blocks/: {', '.join(sorted(blocks))}")
    failed = False
    for name, (ok, messages) in lint(blocks).items():
        print(f"verilator --lint-only {name}.v: {'clean' if ok else 'ERRORS'}")
        if not ok:
            failed = True
            print(messages)
    return 1 if failed else 0
