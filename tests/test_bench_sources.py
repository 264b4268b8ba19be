"""Every benchmark figure records where it comes from (:mod:`flow.bench`), and a figure a model
gives has ``_model`` in its name. Fast: no benchmark is run.

The mechanism is tested on benchmark modules made here (:func:`flow.bench.collect` on them, its
counts, ``python -m flow bench``'s exit status, ``docs/figures.md`` from their ``bench.json``); the
real modules are read with :mod:`ast`: each figure a module gives, where its name or source is
written out, has a source of a known kind, and one whose source is a model's has ``_model`` in
its name.
"""

import ast
import importlib
import inspect
import json
import re
import sys
import types
from pathlib import Path

import pytest

from flow import bench
from flow import figures as figures_doc
from sim.bench import MODULES

#: Figures of every kind, with the kind :func:`flow.bench.kinds` gives each.
MIXED = {
    "fake.gate": ((1, "cycle", "gateware: fake rig, run one"), "gateware"),
    "fake.synth": ((2, "LUT", "synthesis: Yosys"), "synthesis"),
    "fake.proof": ((3, "properties", "formal: SymbiYosys"), "formal"),
    "fake.speed": ((4.5, "ms", "host: the encoder, timed"), "host"),
    "fake.sheet": ((5, "ns", "document: a data sheet"), "document"),
    "fake.rate_model": ((6.0, "Hz", "model: the schedule model"), "model"),
    "fake.rate": ((7.0, "Hz", "model: the schedule model"), "model"),
    "fake.double": ((2, "cycle", "arithmetic: fake.gate x 2"), "gateware"),
    "fake.fraction": ((0.5, "", "arithmetic: fake.gate / fake.rate_model"), "model"),
    "fake.chain": ((1.5, "", "arithmetic: fake.fraction + 1"), "model"),
    "fake.elsewhere": ((1.0, "", "arithmetic: fake.gate / other.bound_model, collected by another run"), "model"),
    "fake.constant": ((1.0, "", "arithmetic: 1 / 1, nothing named"), "arithmetic"),
    "fake.bare": ((8, "cycle"), None),
    "fake.odd": ((9, "cycle", "guessed: a kind nobody knows"), None),
    "fake.empty": ((10, "cycle", ""), None),
}
#: Figures of MIXED without ``_model`` whose kind is ``model``, and those without a source.
FROM_MODEL = {"fake.rate", "fake.fraction", "fake.chain", "fake.elsewhere"}
WITHOUT_SOURCE = {"fake.bare", "fake.odd", "fake.empty"}
SHARED = "gateware: the shared rig"


def _module(name, figures, source=None):
    module = types.ModuleType(name)
    module.run = lambda: dict(figures)
    if source is not None:
        module.SOURCE = source
    return module


@pytest.fixture
def fake_modules(monkeypatch):
    """Benchmark modules ``fake_bench_mixed`` (every kind, no ``SOURCE``), ``fake_bench_shared``
    (pairs and a ``SOURCE``) and ``fake_bench_clean`` (triples, each as it should be)."""
    modules = {
        "fake_bench_mixed": _module("fake_bench_mixed", {k: fig for k, (fig, _) in MIXED.items()}),
        "fake_bench_shared": _module("fake_bench_shared", {"shared.a": (1, "cycle"), "shared.b": (2.5, "Hz"),
                                                           "shared.c_model": (3, "Hz", "model: its own")},
                                     source=SHARED),
        "fake_bench_clean": _module("fake_bench_clean", {
            "clean.rate": (300.0, "Hz", "gateware: the rig"),
            "clean.rate_model": (301.0, "Hz", "model: the schedule model"),
            "clean.fraction_model": (0.99, "", "arithmetic: clean.rate / clean.rate_model"),
        }),
    }
    for name, module in modules.items():
        monkeypatch.setitem(sys.modules, name, module)
    return modules


def _quiet(*_args):
    pass


def test_collect_writes_value_unit_and_source(fake_modules, tmp_path):
    figures = bench.collect(["fake_bench_mixed", "fake_bench_shared"], resources=False, log=_quiet)
    data = json.loads(bench.write(figures, tmp_path / "bench.json").read_text())
    assert set(data) == {*MIXED, "shared.a", "shared.b", "shared.c_model", *bench.CHECKS}
    for name, entry in data.items():
        assert set(entry) == {"value", "unit", "source"}, name
    assert data["fake.gate"] == {"value": 1, "unit": "cycle", "source": "gateware: fake rig, run one"}
    # a pair takes its module's SOURCE; a triple keeps its own; no SOURCE: none
    assert data["shared.a"]["source"] == data["shared.b"]["source"] == SHARED
    assert data["shared.c_model"]["source"] == "model: its own"
    assert data["fake.bare"]["source"] is None


def test_collect_counts_figures_without_source_and_measured_figures_from_a_model(fake_modules):
    logged = []
    figures = bench.collect(["fake_bench_mixed", "fake_bench_shared"], resources=False, log=logged.append)
    kinds = bench.kinds({k: v for k, v in figures.items() if k not in bench.CHECKS})
    assert {name: kinds[name] for name in MIXED} == {name: kind for name, (_, kind) in MIXED.items()}
    assert figures["bench.figures_without_source"]["value"] == len(WITHOUT_SOURCE)
    assert figures["bench.measured_figures_from_model"]["value"] == len(FROM_MODEL)
    for check in bench.CHECKS:
        assert bench.kind(figures[check]["source"]) == "arithmetic"
    # each one is named in the log
    for name in WITHOUT_SOURCE | FROM_MODEL:
        assert any(line.startswith(f"bench: {name}: source") for line in logged), name


def test_a_model_figure_without_model_in_its_name_is_counted(fake_modules, monkeypatch):
    one = _module("fake_bench_one", {"one.rate": (1.0, "Hz", "model: the schedule model")})
    monkeypatch.setitem(sys.modules, "fake_bench_one", one)
    figures = bench.collect(["fake_bench_one"], resources=False, log=_quiet)
    assert figures["bench.measured_figures_from_model"]["value"] == 1
    assert figures["bench.figures_without_source"]["value"] == 0
    # "_model" anywhere in the name is enough (as in store.read_fraction_of_model_bandwidth)
    one.run = lambda: {"one.fraction_of_model_bandwidth": (1.0, "", "model: the memory model")}
    figures = bench.collect(["fake_bench_one"], resources=False, log=_quiet)
    assert figures["bench.measured_figures_from_model"]["value"] == 0


def test_arithmetic_takes_the_weakest_kind_of_its_inputs():
    figures = {
        "a.gate": {"source": "gateware: rig"},
        "a.host": {"source": "host: timed"},
        "a.doc": {"source": "document: data sheet"},
        "a.mixed": {"source": "arithmetic: a.gate / a.host"},
        "a.sheet": {"source": "arithmetic: a.gate x a.doc"},
        "a.loop": {"source": "arithmetic: a.loop2 + 1"},
        "a.loop2": {"source": "arithmetic: a.loop x 2"},
        "a.module": {"source": "arithmetic: spec.schedule.bound over sim.models.mcb_model.v, no figure"},
    }
    kinds = bench.kinds(figures)
    assert kinds["a.mixed"] == "host" and kinds["a.sheet"] == "document"
    assert kinds["a.loop"] == kinds["a.loop2"] == "arithmetic"
    assert kinds["a.module"] == "arithmetic"
    assert bench.kind("Model: upper case") == "model" and bench.kind("gateware") == "gateware"
    assert bench.kind(None) is None and bench.kind("  ") is None and bench.kind("modelled: no") is None


def test_resources_and_timing_figures_are_synthesis(fake_modules, monkeypatch):
    from flow import resources, timing
    monkeypatch.setattr(resources, "report", lambda: {})
    monkeypatch.setattr(resources, "figures", lambda _r: {"res.total.lut": (100, "LUT")})
    monkeypatch.setattr(timing, "report", lambda: {})
    monkeypatch.setattr(timing, "figures", lambda _r: {"timing.dmd.lut_levels_max": (4, "LUT levels")})
    figures = bench.collect(["fake_bench_clean"], resources=True, log=_quiet)
    assert bench.kind(figures["res.total.lut"]["source"]) == "synthesis"
    assert bench.kind(figures["timing.dmd.lut_levels_max"]["source"]) == "synthesis"
    assert figures["bench.figures_without_source"]["value"] == 0
    assert figures["bench.measured_figures_from_model"]["value"] == 0


@pytest.mark.parametrize("modules, status", [(["fake_bench_clean", "fake_bench_shared"], 0),
                                             (["fake_bench_clean", "fake_bench_mixed"], 1)])
def test_bench_exits_1_unless_every_figure_has_a_source_and_model_figures_say_so(
        fake_modules, monkeypatch, tmp_path, capsys, modules, status):
    monkeypatch.chdir(tmp_path)
    assert bench.main(modules, resources=False) == status
    data = json.loads((tmp_path / "build" / "bench.json").read_text())
    assert all("source" in entry for entry in data.values())
    out = capsys.readouterr().out
    if status:
        assert "bench.figures_without_source = 3" in out and "bench.measured_figures_from_model = 4" in out
        for name in WITHOUT_SOURCE | FROM_MODEL:
            assert name in out.splitlines()[-1]


def test_a_merged_run_replaces_only_what_it_measured(fake_modules, monkeypatch, tmp_path, capsys):
    """``--merge`` keeps the figures of the run before (with their commit), replaces those it
    measures now, records the commit of each, and counts the checks over the whole."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(bench, "commit", lambda: "first")
    assert bench.main(["fake_bench_clean", "fake_bench_shared"], resources=False) == 0
    monkeypatch.setattr(bench, "commit", lambda: "second")
    assert bench.main(["fake_bench_mixed"], resources=False, merge=True) == 1
    data = json.loads((tmp_path / "build" / "bench.json").read_text())
    assert data["clean.rate"]["commit"] == "first" and data["shared.a"]["commit"] == "first"
    assert all(data[name]["commit"] == "second" for name in MIXED)
    assert data["bench.figures_without_source"]["value"] == len(WITHOUT_SOURCE)
    assert "`first`" in figures_doc.render(data) and "`second`" in figures_doc.render(data)
    capsys.readouterr()


def test_figures_doc_has_a_table_per_prefix_with_every_figure_and_its_source(tmp_path):
    data = {
        "eth.payload_fraction_of_line_rate": {"value": 0.9916, "unit": "fraction", "source": "gateware: port | pins"},
        "eth.drops_at_line_rate": {"value": 0, "unit": "records", "source": "gateware: port"},
        "seq.gray8_bound_hz_dlp7000_model": {"value": 310.7123456, "unit": "Hz", "source": "model: the bound"},
        "sys.xga_rate_hz_measured": {"value": 280.9, "unit": "Hz", "source": "arithmetic: 200 MHz / sys.period"},
        "store.write_bytes_per_s": {"value": 5.4e8, "unit": "B/s", "source": "gateware: store"},
        "old.figure": {"value": 1, "unit": "x"},
    }
    path = tmp_path / "bench.json"
    path.write_text(json.dumps(data))
    out = figures_doc.write(path, tmp_path / "docs" / "figures.md")
    text = out.read_text()
    lines = text.splitlines()
    assert figures_doc.HEADER in lines[:4]
    assert "python -m flow figures" in figures_doc.HEADER and "build/bench.json" in figures_doc.HEADER
    assert "make bench" in figures_doc.HEADER and "by hand" in figures_doc.HEADER
    headings = [line for line in lines if line.startswith("## ")]
    assert headings == ["## eth", "## old", "## seq", "## store", "## sys"]
    rows = {}
    for line in lines:
        if line.startswith("| `"):
            cells = [c.strip() for c in re.split(r"(?<!\\)\|", line)[1:-1]]
            assert len(cells) == 5, line
            rows[cells[0].strip("`")] = cells
    assert set(rows) == set(data)
    for name, entry in data.items():
        assert rows[name][2] == entry["unit"]
        assert rows[name][3] == entry.get("source", "(no source)").replace("|", "\\|")
    assert rows["seq.gray8_bound_hz_dlp7000_model"][1] == "310.712"
    assert rows["eth.drops_at_line_rate"][1] == "0"
    # each table under its prefix's heading, in name order
    eth = lines.index("## eth")
    assert lines[eth + 2] == "| figure | value | unit | source | commit |"
    assert rows["eth.drops_at_line_rate"][4] == "`not recorded`"
    assert lines[eth + 4].startswith("| `eth.drops_at_line_rate`")
    assert lines[eth + 5].startswith("| `eth.payload_fraction_of_line_rate`")


def test_a_merged_run_in_a_fresh_clone_starts_from_the_figures_page(fake_modules, monkeypatch, tmp_path, capsys):
    """With no ``build/bench.json``, ``--merge`` keeps what ``docs/figures.md`` records: each
    figure's value as the page shows it, its source and its commit."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(bench, "commit", lambda: "first")
    assert bench.main(["fake_bench_clean", "fake_bench_shared"], resources=False) == 0
    figures_doc.write("build/bench.json", "docs/figures.md")
    first = json.loads((tmp_path / "build" / "bench.json").read_text())
    (tmp_path / "build" / "bench.json").unlink()
    monkeypatch.setattr(bench, "commit", lambda: "second")
    assert bench.main(["fake_bench_mixed"], resources=False, merge=True) == 1
    data = json.loads((tmp_path / "build" / "bench.json").read_text())
    for name, entry in first.items():
        if name not in bench.CHECKS:
            assert data[name]["commit"] == "first" and data[name]["source"] == entry["source"]
            assert figures_doc.quoted(data[name]) == figures_doc.quoted(entry)
    assert all(data[name]["commit"] == "second" for name in MIXED)
    capsys.readouterr()


def test_the_page_reads_back_as_it_was_written():
    """``docs/figures.md`` as committed, read back (:func:`flow.figures.recorded`) and rendered
    again, is the same page: a merge that starts from it loses nothing."""
    page = (Path(__file__).parent.parent / "docs" / "figures.md").read_text()
    assert figures_doc.render(figures_doc.recorded(page)) == page


def test_figures_doc_needs_bench_json(tmp_path, monkeypatch, capsys):
    with pytest.raises(FileNotFoundError, match="make bench"):
        figures_doc.write(tmp_path / "build" / "bench.json", tmp_path / "docs" / "figures.md")
    assert not (tmp_path / "docs").exists()
    from flow.cli import main
    monkeypatch.chdir(tmp_path)
    assert main(["figures"]) == 2
    assert "make bench" in capsys.readouterr().err


# -- the real modules, read with ast -------------------------------------------------------------

#: Every module whose figures ``make bench`` collects (group orders' through the rates bench).
BENCH_MODULES = [*MODULES, "sim.bench.group_orders_figures"]
_FIGURE = re.compile(r"^[a-z_0-9]+\.")


def _strings(node):
    """Every string constant in the expression ``node``."""
    return [n.value for n in ast.walk(node) if isinstance(n, ast.Constant) and isinstance(n.value, str)]


def _looks_like_figure(node):
    """A figure name written out: a string, or an f-string, starting ``<prefix>.``."""
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        return bool(_FIGURE.match(node.value))
    if isinstance(node, ast.JoinedStr) and node.values and isinstance(node.values[0], ast.Constant):
        return bool(_FIGURE.match(node.values[0].value))
    return False


def _source_text(node, module):
    """The start of a source expression where it can be read without running it: a string, an
    f-string, a module constant, ``CONSTANT.format(...)``, ``a + b``; None otherwise."""
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        return node.value
    if isinstance(node, ast.JoinedStr) and node.values:
        first = node.values[0]
        return first.value if isinstance(first, ast.Constant) else _source_text(first.value, module)
    if isinstance(node, ast.Name):
        value = getattr(module, node.id, None)
        return value if isinstance(value, str) else None
    if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and node.func.attr == "format":
        return _source_text(node.func.value, module)
    if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Add):
        return _source_text(node.left, module)
    return None


def _figure_sites(tree):
    """(name node, value node) of every ``{name: (...)}`` entry and ``x[name] = (...)`` whose
    value is a tuple."""
    for node in ast.walk(tree):
        if isinstance(node, ast.Dict):
            for key, value in zip(node.keys, node.values, strict=True):
                if key is not None and isinstance(value, ast.Tuple):
                    yield key, value
        elif isinstance(node, ast.Assign) and isinstance(node.value, ast.Tuple):
            for target in node.targets:
                if isinstance(target, ast.Subscript):
                    yield target.slice, node.value


def _is_figure(key, value):
    """A figure tuple: its name written out, or a string unit second."""
    second = value.elts[1] if len(value.elts) > 1 else None
    unit = isinstance(second, (ast.Constant, ast.JoinedStr)) and (
        not isinstance(second, ast.Constant) or isinstance(second.value, str))
    return _looks_like_figure(key) or (len(value.elts) in (2, 3) and unit)


@pytest.mark.parametrize("name", BENCH_MODULES)
def test_every_figure_a_bench_module_gives_has_a_source(name):
    module = importlib.import_module(name)
    shared = getattr(module, "SOURCE", bench.SOURCES.get(name))
    if shared is not None:
        assert bench.kind(shared) in bench.KINDS, f"{name}: SOURCE {shared!r} names no kind"
    if name in bench.SOURCES:
        return                      # (its figures come from elsewhere; its SOURCE is here)
    tree = ast.parse(inspect.getsource(module))
    sites = [(key, value) for key, value in _figure_sites(tree) if _is_figure(key, value)]
    if name != "sim.bench.group_orders_figures":
        assert sites, f"{name}: no figure found"
    for key, value in sites:
        where = f"{name}:{value.lineno}"
        if shared is None:
            assert len(value.elts) == 3, f"{where}: a figure without a source (and the module has no SOURCE)"
        if len(value.elts) != 3:
            continue
        text = _source_text(value.elts[2], module)
        if text is None:
            continue                # (a variable: the run of the module checks it)
        kind = bench.kind(text)
        assert kind is not None, f"{where}: source {text!r} names no kind ({', '.join(bench.KINDS)}, arithmetic)"
        if kind == "model" and isinstance(key, (ast.Constant, ast.JoinedStr, ast.BinOp)):
            assert any("_model" in s for s in _strings(key)), \
                f"{where}: a model's figure without _model in its name ({ast.unparse(key)})"


def test_figures_write_the_readmes_headline_block_only(tmp_path):
    """``make figures`` writes the README's headline figures between its markers and leaves the
    rest of the page alone; a headline the run did not give is said to be missing."""
    data = {"sys.xga_rate_hz_measured": {"value": 280.89, "unit": "Hz", "source": "gateware: run"}}
    bench_json = tmp_path / "bench.json"
    bench_json.write_text(json.dumps(data))
    readme = tmp_path / "README.md"
    readme.write_text(f"before\n{figures_doc.README_BEGIN}\nstale\n{figures_doc.README_END}\nafter\n")
    figures_doc.write(bench_json, tmp_path / "figures.md", readme)
    text = readme.read_text()
    assert text.startswith("before\n") and text.endswith(f"{figures_doc.README_END}\nafter\n")
    assert "stale" not in text and "| `sys.xga_rate_hz_measured` | 280.89 Hz |" in text
    assert text.count("missing from the last make bench") == len(figures_doc.HEADLINES) - 1
    # the page's figures read back as they were written
    page = figures_doc.parse((tmp_path / "figures.md").read_text())
    assert page == {"sys.xga_rate_hz_measured": {"value": "280.89", "unit": "Hz", "source": "gateware: run",
                                                "commit": "not recorded"}}

