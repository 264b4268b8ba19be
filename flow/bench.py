"""``make bench``: run every benchmark, add the resource figures, write ``build/bench.json``.

``build/bench.json`` is one flat JSON object:
``{"<figure>": {"value": number, "unit": "...", "source": "..."}}``. The same figures are printed
as a table (``python -m flow figures`` writes them to ``docs/figures.md``).

Every figure records where it comes from. A benchmark's ``run()`` gives ``{figure: (value, unit,
source)}``, or ``(value, unit)`` where the module's ``SOURCE`` (or :data:`SOURCES`) holds the
source all its figures share. A source is a short text whose first word is its kind
(:data:`KINDS`): ``gateware`` (a simulation of the design or its generated Verilog), ``synthesis``
(Yosys on the gateware), ``formal`` (SymbiYosys on the gateware), ``host`` (host code measured in
Python), ``document`` (a data sheet's number), ``model`` (a Python model: the schedule model, the
camera model on model output, ...) or ``arithmetic`` (derived from the figures it names; its kind
is the weakest of theirs, so arithmetic on a model figure is a model figure; a name ending in
``_model`` counts as a model figure's even when this run did not collect it).

A figure without ``_model`` in its name is measured on the gateware: :func:`collect` adds
``bench.figures_without_source`` (figures with no source, or one of no known kind) and
``bench.measured_figures_from_model`` (figures without ``_model`` whose kind is ``model``); both
must be 0, and ``python -m flow bench`` exits 1 if either is not.
"""

import importlib
import json
import math
import re
import time
from pathlib import Path

__all__ = ["collect", "write", "print_table", "main", "earlier", "kind", "kinds", "KINDS", "SOURCES", "CHECKS"]

#: The kinds of source, strongest first: arithmetic takes the weakest of its inputs'.
KINDS = ("gateware", "synthesis", "formal", "host", "document", "model")
ARITHMETIC = "arithmetic"
#: Sources of benchmark modules that give ``(value, unit)`` and have no ``SOURCE`` of their own.
SOURCES = {
    "sim.bench.formal_figures": "formal: SymbiYosys on the gateware, every property of sim.formal.suite at its full "
                        "depth (as make formal)",
}
#: The figures :func:`collect` adds about the others' sources (both must be 0).
CHECKS = ("bench.figures_without_source", "bench.measured_figures_from_model")
_NAME = re.compile(r"[A-Za-z_][\w]*(?:\.\w+)+")
RESOURCES_SOURCE = "synthesis: Yosys synth_xilinx -family xc6s, per block and board build (flow.resources)"
TIMING_SOURCE = "synthesis: Yosys synth_xilinx -family xc6s, logic depth per clock domain (flow.timing)"


def kind(source):
    """The kind a source names (its first word), or None when it names none of :data:`KINDS` or
    ``arithmetic``."""
    if not isinstance(source, str) or not source.split():
        return None
    word = source.split()[0].rstrip(":,;").lower()
    return word if word in KINDS or word == ARITHMETIC else None


def _inputs(source, figures):
    """The figures an arithmetic source names: those collected, and names ending in ``_model``."""
    return [n for n in _NAME.findall(source.split(None, 1)[1] if len(source.split()) > 1 else "")
            if n in figures or n.endswith("_model")]


def kinds(figures):
    """Each figure's kind: its source's, arithmetic resolved to the weakest kind of the figures it
    names (``arithmetic`` if it names none this run knows; None: no source of a known kind)."""
    out = {}

    def resolve(name, seen):
        if name in out:
            return out[name]
        if name not in figures:               # a _model figure another run collects
            return "model"
        source = figures[name].get("source")
        k = kind(source)
        if k == ARITHMETIC:
            ranks = [resolve(n, seen | {name}) for n in _inputs(source, figures) if n not in seen | {name}]
            ranks = [r for r in ranks if r in KINDS]
            k = max(ranks, key=KINDS.index) if ranks else ARITHMETIC
        out[name] = k
        return k

    for name in figures:
        resolve(name, frozenset())
    return out


def _check(figures):
    """The figures with no source, and those without ``_model`` whose kind is ``model``."""
    k = kinds(figures)
    missing = sorted(n for n in figures if k[n] is None)
    from_model = sorted(n for n in figures if k[n] == "model" and "_model" not in n)
    return missing, from_model


def collect(modules=None, *, resources=True, log=print):
    from sim.bench import MODULES
    figures = {}
    for name in modules or MODULES:
        start = time.monotonic()
        log(f"bench: {name} ...")
        module = importlib.import_module(name)
        default = getattr(module, "SOURCE", SOURCES.get(name))
        for key, figure in module.run().items():
            value, unit, source = (*figure, default) if len(figure) == 2 else figure
            if not isinstance(value, (int, float)) or (isinstance(value, float) and not math.isfinite(value)):
                raise ValueError(f"{name}: figure {key} is not a finite number: {value!r}")
            figures[key] = {"value": value, "unit": unit, "source": source}
        log(f"bench: {name} done in {time.monotonic() - start:.1f} s")
    if resources:
        from flow import resources as res
        log("bench: resources (yosys synth_xilinx -family xc6s) ...")
        for key, (value, unit) in res.figures(res.report()).items():
            figures[key] = {"value": value, "unit": unit, "source": RESOURCES_SOURCE}
        from flow import timing
        log("bench: logic depth per clock domain (yosys synth_xilinx -family xc6s) ...")
        for key, (value, unit) in timing.figures(timing.report()).items():
            figures[key] = {"value": value, "unit": unit, "source": TIMING_SOURCE}
    missing, from_model = _check(figures)
    for what, names in (("no source", missing), ("a model's, without _model in its name", from_model)):
        for key in names:
            log(f"bench: {key}: source {what}")
    _count_checks(figures, missing, from_model)
    return figures


def _count_checks(figures, missing, from_model, **extra):
    """Write :data:`CHECKS` into ``figures``: how many have no source, and how many are a model's
    without ``_model`` in their name (``extra``: more fields of each, such as its commit)."""
    counted = "arithmetic: counted by flow.bench.collect over this run's figures' names and sources"
    for key, names in zip(CHECKS, (missing, from_model), strict=True):
        figures[key] = {"value": len(names), "unit": "figures", "source": counted, **extra}


def write(figures, path="build/bench.json"):
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(figures, indent=2, sort_keys=True) + "\n")
    return path


def print_table(figures):
    width = max(len(k) for k in figures)
    units = min(24, max(len(str(f["unit"])) for f in figures.values()))
    for key in sorted(figures):
        value, unit = figures[key]["value"], figures[key]["unit"]
        text = f"{value:.6g}" if isinstance(value, float) else str(value)
        print(f"{key:<{width}}  {text:>14}  {unit:<{units}}  {figures[key].get('source') or '(no source)'}")


def commit():
    """The commit the figures are measured on (short hash, ``-dirty`` when the tree has changes),
    or None outside a git work tree."""
    import subprocess
    try:
        head = subprocess.run(["git", "rev-parse", "--short=12", "HEAD"], capture_output=True, text=True,
                              check=True).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"], capture_output=True,
                               text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return None
    return head + ("-dirty" if dirty else "")


def earlier(path="build/bench.json", page="docs/figures.md"):
    """The figures a ``--merge`` run keeps: ``path`` as the last run wrote it, or, in a clone where
    no run wrote it, the figures page committed beside the code (:func:`flow.figures.recorded`:
    every figure with its value as the page shows it, its source and its commit); {} if neither."""
    if Path(path).exists():
        return json.loads(Path(path).read_text())
    if Path(page).exists():
        from flow import figures as figures_page
        return figures_page.recorded(Path(page).read_text())
    return {}


def main(modules=None, resources=True, path="build/bench.json", merge=False):
    """Collect, write and print the figures; 1 if a figure has no source or a model's figure
    lacks ``_model`` in its name (:data:`CHECKS`), else 0. Each figure records the
    :func:`commit` it was measured on. ``merge``: the figures of the modules run (and the synthesis
    figures, with ``resources``) replace theirs in the ``path`` written before, the others kept as
    they were (each with its own commit; :func:`earlier`); the checks are counted again over the whole."""
    figures = collect(modules, resources=resources)
    measured_on = commit()
    for key in figures:
        figures[key]["commit"] = measured_on
    if merge:
        before = earlier(path)
        figures = {**{k: v for k, v in before.items() if k not in CHECKS}, **figures}
        _count_checks(figures, *_check({k: v for k, v in figures.items() if k not in CHECKS}), commit=measured_on)
    path = write(figures, path)
    print_table(figures)
    print(f"wrote {path}")
    bad = {key: figures[key]["value"] for key in CHECKS if figures[key]["value"]}
    if bad:
        missing, from_model = _check({k: v for k, v in figures.items() if k not in CHECKS})
        print("bench: " + ", ".join(f"{key} = {n}" for key, n in bad.items()) + " (must be 0): "
              + ", ".join(missing + from_model))
        return 1
    return 0
