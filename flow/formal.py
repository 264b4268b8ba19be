"""``make formal``: every formal property (SymbiYosys with Yices, from PyPI), its table, and
``build/formal/results.json``.

Each row is a property of a block, proven by k-induction or checked by BMC to a depth, or proven
structurally, with the covers of what it is about and the step each is first reached at; a
failing row (an assertion that fails, or a cover not reached at the row's depth) names what
failed and its counterexample VCD, and the command exits 1. A whole run (every block) also
writes the table of ``docs/formal.md`` from its rows, between the page's markers.
"""

import json
from pathlib import Path

from sim.formal.suite import RESULTS, figures, run_all
from sim.harness.paths import build_dir

__all__ = ["main", "table"]

DOC = Path(__file__).resolve().parents[1] / "docs" / "formal.md"
BEGIN, END = "<!-- rows: written by make formal -->", "<!-- end of rows -->"


def _kind(row):
    if row["method"] == "structural":
        return "proof, structural (all states)"
    if row["status"] == "proven":
        return f"proof, k-induction at k = {row['depth']}"
    if row["status"] == "checked":
        return f"bounded, BMC to {row['depth']} steps"
    return "FAILED"


def table(rows):
    """The Markdown table of ``rows`` (``results.json``'s dicts): one row per property, its
    kind, its covers and the step each is first reached at."""
    lines = ["| Block | Property | Kind | Covers (first reached at step) | Seconds |", "|---|---|---|---|---|"]
    for row in rows:
        covers = "; ".join(f"{message}: {'not reached' if step is None else step}"
                           for message, step in sorted(row["covers"].items(), key=lambda item: (item[1] is None,
                                                                                                 item[1] or 0)))
        if row["method"] == "structural":
            covers = "(no event: it holds of the netlist)"
        lines.append(f"| {row['block']} | {row['name']} | {_kind(row)} | {covers.replace('|', '/')} "
                     f"| {row['seconds']:.0f} |")
    return "\n".join(lines)


def _write_doc(rows):
    text = DOC.read_text()
    if BEGIN not in text or END not in text:
        return
    head, rest = text.split(BEGIN, 1)
    _, tail = rest.split(END, 1)
    DOC.write_text(f"{head}{BEGIN}\n{table(rows)}\n{END}{tail}")


def main(*, quick=False, only=None, jobs=1):
    rows = run_all(quick=quick, only=only, jobs=jobs)
    # a whole full-depth run's rows are the ones the bench and the page quote (RESULTS)
    path = build_dir("formal") / (RESULTS if not quick and not only else "results-partial.json")
    records = [row.__dict__ for row in rows]
    path.write_text(json.dumps(records, indent=2) + "\n")
    for name, (value, unit) in figures(rows).items():
        print(f"{name} = {value:g} {unit}")
    print(f"wrote {path}")
    if not quick and not only:
        _write_doc(records)
        print(f"wrote the table of {DOC.relative_to(DOC.parents[1])}")
    failed = [row for row in rows if row.status == "failed"]
    for row in failed:
        print(f"FAILED {row.block}: {row.name}: {row.detail}")
    return 1 if failed else 0
