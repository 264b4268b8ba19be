"""Figures quoted in the pages (``<!-- figure NAME:SPEC UNIT -->...<!-- /figure -->``) are written
by ``make figures`` from ``build/bench.json``, never by hand. Fast: no benchmark is run.

The mechanism is tested on a small bench.json made here; every marker in ``docs/*.md`` and the
README must name a figure some benchmark module gives (the names each module builds, read with
:mod:`ast`, and the names in ``build/bench.json`` when there is one), and hold what the script
would write from ``docs/figures.md`` (or the placeholder while there is none).
"""

import ast
import importlib
import inspect
import json
import re
from pathlib import Path

import pytest

from flow import bench
from flow import figures as figures_doc
from sim.bench import MODULES

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md", *sorted(p for p in (ROOT / "docs").glob("*.md") if p.name != "figures.md")]

FAKE = {
    "seq.rate_hz": {"value": 302.0937, "unit": "Hz", "source": "gateware: rig"},
    "seq.fraction_model": {"value": 0.97234, "unit": "", "source": "model: plan"},
    "seq.frame_cycles": {"value": 661952, "unit": "cycle", "source": "gateware: rig"},
    "seq.big": {"value": 1234567.0, "unit": "B/s", "source": "gateware: rig"},
}
PAGE = ("A rate of <!-- figure seq.rate_hz:.1f Hz -->stale<!-- /figure --> "
        "(<!-- figure seq.fraction_model:.1% -->1 %<!-- /figure --> of the bound), "
        "<!-- figure seq.frame_cycles:,.0f cycles --><!-- /figure -->, "
        "<!-- figure seq.rate_hz -->x<!-- /figure --> plain, "
        "<!-- figure seq.big:.3g -->x<!-- /figure -->, and <!-- figure seq.gone:.1f Hz -->9 Hz<!-- /figure -->.\n")
WRITTEN = ("A rate of <!-- figure seq.rate_hz:.1f Hz -->302.1 Hz<!-- /figure --> "
           "(<!-- figure seq.fraction_model:.1% -->97.2 %<!-- /figure --> of the bound), "
           "<!-- figure seq.frame_cycles:,.0f cycles -->661,952 cycles<!-- /figure -->, "
           "<!-- figure seq.rate_hz -->302.094<!-- /figure --> plain, "
           "<!-- figure seq.big:.3g -->1.23e+06<!-- /figure -->, and "
           f"<!-- figure seq.gone:.1f Hz -->{figures_doc.PLACEHOLDER}<!-- /figure -->.\n")


def test_figures_rewrites_every_marker_of_the_pages_and_the_readme(tmp_path):
    bench_json = tmp_path / "bench.json"
    bench_json.write_text(json.dumps(FAKE))
    docs = tmp_path / "docs"
    docs.mkdir()
    (docs / "a.md").write_text(PAGE)
    (docs / "b.md").write_text("no figure here\n")
    (docs / "notes.txt").write_text(PAGE)
    readme = tmp_path / "README.md"
    readme.write_text(f"top\n{figures_doc.README_BEGIN}\n{figures_doc.README_END}\n{PAGE}")
    out = figures_doc.write(bench_json, docs / "figures.md", readme, docs)
    assert (docs / "a.md").read_text() == WRITTEN
    assert (docs / "b.md").read_text() == "no figure here\n"
    assert (docs / "notes.txt").read_text() == PAGE            # (pages are the Markdown ones)
    assert readme.read_text().endswith(WRITTEN) and "missing from the last make bench" in readme.read_text()
    # the figures page is left as render wrote it; writing again changes nothing
    assert out.read_text() == figures_doc.render(FAKE)
    figures_doc.write(bench_json, docs / "figures.md", readme, docs)
    assert (docs / "a.md").read_text() == WRITTEN
    # the same text from the figures page's values as from bench.json's
    assert figures_doc.quote(PAGE, figures_doc.parse(out.read_text())) == WRITTEN


def test_a_format_that_does_not_fit_names_its_marker():
    with pytest.raises(ValueError, match="seq.rate_hz:,d"):
        figures_doc.quote("<!-- figure seq.rate_hz:,d -->x<!-- /figure -->", FAKE)
    assert figures_doc.markers(PAGE)[0] == ("seq.rate_hz", ".1f", "Hz", "stale")
    assert figures_doc.markers(PAGE)[3] == ("seq.rate_hz", None, None, "x")


def test_no_bench_json_leaves_every_page_alone(tmp_path):
    docs = tmp_path / "docs"
    docs.mkdir()
    (docs / "a.md").write_text(PAGE)
    with pytest.raises(FileNotFoundError, match="make bench"):
        figures_doc.write(tmp_path / "build" / "bench.json", docs / "figures.md", None, docs)
    assert (docs / "a.md").read_text() == PAGE and not (docs / "figures.md").exists()


# -- the names the benchmark modules give, read with ast ---------------------------------------

#: Every module whose figures ``make bench`` collects (group orders' through the rates bench, the
#: synthesis figures through flow.bench).
NAMING_MODULES = [*MODULES, "sim.bench.group_orders_figures", "flow.resources", "flow.timing"]
_ANY = "\0"                         # a part of a name the module computes (a loop's key, a suffix)
_PREFIX = re.compile(r"^[a-z_0-9]+\.")


class _Names:
    """The figure names a module builds, as templates: strings in which :data:`_ANY` stands for
    a part computed at run time. Reads string constants, f-strings, ``a + b``, ``x if c else
    y``, ``name.replace(a, b)``, names assigned a string (anywhere in the module) and calls of
    functions that return one (``bound_figure(...)``)."""

    def __init__(self, module):
        self.module = module
        self.tree = ast.parse(inspect.getsource(module))
        self.assigned, plain = {}, set()
        for node in ast.walk(self.tree):
            if isinstance(node, ast.Assign):
                for target in node.targets:
                    if isinstance(target, ast.Name):
                        self.assigned.setdefault(target.id, []).append(node.value)
                        plain.add(id(target))
        # a name also bound otherwise (a loop's target, an argument, unpacking) may be anything
        for node in ast.walk(self.tree):
            stored = isinstance(node, ast.Name) and isinstance(node.ctx, ast.Store) and id(node) not in plain
            bound = node.id if stored else node.arg if isinstance(node, ast.arg) else None
            if bound is not None:
                self.assigned.setdefault(bound, []).append(ast.Constant(_ANY))
        self.busy = set()

    def of(self, node):
        """The templates ``node`` may evaluate to (a list; [_ANY] where nothing is known)."""
        if isinstance(node, ast.Constant):
            return [node.value] if isinstance(node.value, str) else [_ANY]
        if isinstance(node, ast.JoinedStr):
            out = [""]
            for part in node.values:
                tails = self.of(part.value) if isinstance(part, ast.FormattedValue) else self.of(part)
                out = [head + tail for head in out for tail in tails]
            return out
        if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Add):
            return [a + b for a in self.of(node.left) for b in self.of(node.right)]
        if isinstance(node, ast.IfExp):
            return self.of(node.body) + self.of(node.orelse)
        if isinstance(node, ast.Name) and node.id in self.assigned and node.id not in self.busy:
            self.busy.add(node.id)
            try:
                return [t for value in self.assigned[node.id] for t in self.of(value)]
            finally:
                self.busy.discard(node.id)
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and node.func.attr == "replace" \
                and len(node.args) == 2 and all(isinstance(a, ast.Constant) for a in node.args):
            old, new = (a.value for a in node.args)
            return [t.replace(old, new) for t in self.of(node.func.value)]
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Name):
            function = getattr(self.module, node.func.id, None)
            if inspect.isfunction(function) and function.__module__ != self.module.__name__:
                return _Names(importlib.import_module(function.__module__)).returns(function.__name__)
            return self.returns(node.func.id)
        return [_ANY]

    def returns(self, function):
        """The templates the module's function ``function`` returns."""
        if function in self.busy:
            return [_ANY]
        self.busy.add(function)
        try:
            out = [t for node in ast.walk(self.tree) if isinstance(node, ast.FunctionDef) and node.name == function
                   for ret in ast.walk(node) if isinstance(ret, ast.Return) and ret.value is not None
                   for t in self.of(ret.value)]
        finally:
            self.busy.discard(function)
        return out or [_ANY]

    def figures(self):
        """The templates of every figure name the module writes: each dict key and each
        subscript assigned to, that starts ``<prefix>.``."""
        keys = []
        for node in ast.walk(self.tree):
            if isinstance(node, ast.Dict):
                keys += [key for key in node.keys if key is not None]
            elif isinstance(node, ast.Assign):
                keys += [target.slice for target in node.targets if isinstance(target, ast.Subscript)]
        return {t for key in keys for t in self.of(key) if _PREFIX.match(t)}


def _pattern(template):
    return re.compile("".join(r"\w*" if part == _ANY else re.escape(part)
                              for part in re.split(f"({_ANY})", template)) + "$")


def _given():
    patterns = [_pattern(t) for name in NAMING_MODULES for t in _Names(importlib.import_module(name)).figures()]
    return patterns + [_pattern(name) for name in bench.CHECKS]


def _quoted():
    """(page, name, spec, unit, text) of every marker in the README and ``docs/*.md``."""
    return [(page.name, *marker) for page in PAGES for marker in figures_doc.markers(page.read_text())]


def test_the_names_read_from_the_modules_include_those_built_in_loops():
    patterns = _given()
    for name in ("seq.gray8_bound_hz_dlp7000_model", "seq.gray8_bound_hz_dlp9500_400mhz_model",
                 "seq.gray8_fraction_of_bound_dlp7000_dual_200mhz_group_orders_chained_model",
                 "seq.gray8_group_orders_hz_limit_dlp7000_dual_400mhz_ddr2_model", "eth.xga_frames_per_s",
                 "sys.xga_rate_hz_measured", "res.top.lut", "bench.figures_without_source"):
        assert any(p.match(name) for p in patterns), name
    # (a part computed at run time matches any word: seq.gray8_rate_hz_<key> is any such name)
    for name in ("seq.gray8_rate_hx_dlp7000", "seq.gray8_group_orders_hz_dlp7000_quad_200mhz_model",
                 "sys.xga_rate_hz", "nothing.at_all"):
        assert not any(p.match(name) for p in patterns), name


def test_every_quoted_figure_is_one_a_bench_module_gives():
    patterns = _given()
    quoted = _quoted()
    assert quoted, "no page quotes a figure"
    unknown = sorted({(page, name) for page, name, *_ in quoted if not any(p.match(name) for p in patterns)})
    assert not unknown, f"figures no benchmark module gives: {unknown}"
    bench_json = ROOT / "build" / "bench.json"
    if bench_json.is_file():
        # the last make bench: each quoted figure among its names (unless it ran some modules only)
        given = json.loads(bench_json.read_text())
        missing = sorted({(page, name) for page, name, *_ in quoted if name not in given})
        assert not missing, f"figures the last make bench did not give: {missing}"


def test_every_quoted_figure_is_what_make_figures_writes():
    """A figure in a page is the one ``docs/figures.md`` shows, in the marker's format (a hand
    edit fails); with no figures page yet, every marker holds the placeholder."""
    quoted = _quoted()
    page_path = ROOT / "docs" / "figures.md"
    if not page_path.exists():
        wrong = [(page, name, text) for page, name, _spec, _unit, text in quoted if text != figures_doc.PLACEHOLDER]
        assert not wrong, f"figures written by hand before make figures: {wrong}"
        pytest.skip("docs/figures.md not written yet (make bench, then make figures): every marker a placeholder")
    figures = figures_doc.parse(page_path.read_text())
    wrong = [(page, name, text, figures_doc.quoted(figures.get(name), spec, unit))
             for page, name, spec, unit, text in quoted
             if text != figures_doc.quoted(figures.get(name), spec, unit)]
    assert not wrong, f"(page, figure, text, what make figures writes): {wrong}"
