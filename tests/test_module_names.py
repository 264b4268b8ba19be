"""The simulation's file names say what each module is and are unique in the repository (the
scheme is ``sim/__init__.py``'s): a cocotb testbench ends in ``_tb`` and names the test that runs
it, and that test names it; a benchmark ends in ``_figures``. Fast: modules are read with
:mod:`ast`, none is imported but the benchmark list."""

import ast
import re
from collections import Counter
from pathlib import Path

from sim.bench import MODULES

ROOT = Path(__file__).resolve().parents[1]
TOPS = ("spec", "gateware", "host", "sim", "flow", "tests")
SPECIAL = {"__init__.py", "__main__.py"}


def _files(*tops):
    return [p for top in tops for p in sorted((ROOT / top).rglob("*.py")) if p.name not in SPECIAL]


def _is_cocotb_test(node):
    return any("cocotb.test" in ast.unparse(d) for d in getattr(node, "decorator_list", ()))


def test_sim_file_names_are_unique_in_the_repository():
    """No file name under ``sim/`` is used anywhere else in the repository."""
    counts = Counter(p.name for p in _files(*TOPS))
    clashes = sorted(str(p.relative_to(ROOT)) for p in _files("sim") if counts[p.name] > 1)
    assert not clashes, clashes


def test_formal_modules_end_in_properties():
    """A module of ``sim/formal`` that states properties of gateware ends in ``_properties``; the
    others are the machinery that runs them."""
    machinery = {"harness.py", "suite.py", "tools.py", "geometry.py"}
    wrong = [p.name for p in _files("sim/formal") if p.name not in machinery and not p.stem.endswith("_properties")]
    assert not wrong, wrong


def test_testbenches_end_in_tb_and_name_their_tests():
    """A module of ``sim/tb`` has cocotb tests exactly when its name ends in ``_tb``, and its
    docstring names a test module (``tests/test_*.py``) that exists."""
    wrong, unnamed = [], []
    for path in _files("sim/tb"):
        tree = ast.parse(path.read_text())
        if any(_is_cocotb_test(node) for node in tree.body) != path.stem.endswith("_tb"):
            wrong.append(path.name)
        elif path.stem.endswith("_tb"):
            named = re.findall(r"tests/(test_\w+\.py)", ast.get_docstring(tree) or "")
            if not any((ROOT / "tests" / name).exists() for name in named):
                unnamed.append(path.name)
    assert not wrong, f"cocotb tests without _tb, or _tb without cocotb tests: {wrong}"
    assert not unnamed, f"testbenches whose docstring names no test module: {unnamed}"


def test_tests_name_the_testbenches_they_run():
    """A test module that runs a testbench (``module="sim.tb.<name>_tb"``) names it in its
    docstring, and the testbench exists."""
    missing = []
    for path in _files("tests"):
        text = path.read_text()
        doc = ast.get_docstring(ast.parse(text)) or ""
        for module in set(re.findall(r'module="(sim\.tb\.\w+)"', text)):
            if not (ROOT / (module.replace(".", "/") + ".py")).exists() or module not in doc:
                missing.append(f"{path.name}: {module}")
    assert not missing, missing


def test_benchmarks_end_in_figures():
    """Every module ``make bench`` runs is a ``sim/bench/*_figures.py``, and every such module
    gives figures (``run()``; ``group_orders_figures``'s are collected through ``rates_figures``)."""
    found = {f"sim.bench.{p.stem}": p for p in _files("sim/bench") if p.stem.endswith("_figures")}
    assert set(MODULES) <= set(found), sorted(set(MODULES) - set(found))
    without = [name for name, path in found.items()
               if not any(isinstance(node, ast.FunctionDef) and node.name == "run"
                          for node in ast.parse(path.read_text()).body)]
    assert not without, without
