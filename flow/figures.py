"""``make figures``: ``docs/figures.md`` from ``build/bench.json``, a table per figure prefix.

``build/bench.json`` is what ``make bench`` writes (:mod:`flow.bench`): every figure with its
value, unit and source. The prefix is a figure name's part before its first dot (``eth``,
``seq``, ``sys``, ``store``, ...); each table lists its figures in name order with their value,
unit and source.
"""

import json
from pathlib import Path

__all__ = ["render", "write", "main", "HEADER"]

HEADER = ("Written by `python -m flow figures` from `build/bench.json` (the output of `make bench`); "
          "do not edit by hand.")


def _cell(text):
    """``text`` fit for a Markdown table cell."""
    return str(text).replace("\\", "\\\\").replace("|", "\\|").replace("\n", " ")


def _value(value):
    if isinstance(value, bool) or not isinstance(value, float):
        return str(value)
    return f"{value:.6g}"


def render(figures):
    """The Markdown of ``figures`` (``{name: {"value", "unit", "source"}}``)."""
    groups = {}
    for name in sorted(figures):
        groups.setdefault(name.split(".", 1)[0], []).append(name)
    lines = ["# Figures", "", HEADER, ""]
    for prefix in sorted(groups):
        lines += [f"## {prefix}", "", "| figure | value | unit | source |", "|---|---|---|---|"]
        for name in groups[prefix]:
            entry = figures[name]
            lines.append(f"| `{_cell(name)}` | {_cell(_value(entry.get('value')))} | {_cell(entry.get('unit', ''))} "
                         f"| {_cell(entry.get('source') or '(no source)')} |")
        lines.append("")
    return "\n".join(lines)


def write(bench="build/bench.json", out="docs/figures.md"):
    """Read ``bench`` and write ``out``; returns its path. FileNotFoundError if ``bench`` is
    missing (``make bench`` writes it)."""
    bench, out = Path(bench), Path(out)
    if not bench.is_file():
        raise FileNotFoundError(f"{bench} not found: run `make bench` (python -m flow bench) first, it writes "
                                f"the figures {out} is made from")
    figures = json.loads(bench.read_text())
    if not isinstance(figures, dict) or not all(isinstance(v, dict) and "value" in v for v in figures.values()):
        raise ValueError(f"{bench} is not a bench.json of make bench: {{figure: {{value, unit, source}}}}")
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(render(figures))
    return out


def main(bench="build/bench.json", out="docs/figures.md"):
    path = write(bench, out)
    print(f"wrote {path}")
    return 0
