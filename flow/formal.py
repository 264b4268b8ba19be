"""``make formal``: every formal property (SymbiYosys with Yices, from PyPI), its table, and
``build/formal/results.json``.

Each row is a property of a block, proven by k-induction or checked by BMC to a depth, or proven
structurally; a failing row names the failed assertion and its counterexample VCD, and the
command exits 1.
"""

import json

from sim.formal.suite import figures, run_all
from sim.harness.paths import build_dir

__all__ = ["main"]


def main(*, quick=False, only=None):
    rows = run_all(quick=quick, only=only)
    path = build_dir("formal") / "results.json"
    path.write_text(json.dumps([row.__dict__ for row in rows], indent=2) + "\n")
    for name, (value, unit) in figures(rows).items():
        print(f"{name} = {value:g} {unit}")
    print(f"wrote {path}")
    failed = [row for row in rows if row.status == "failed"]
    for row in failed:
        print(f"FAILED {row.block}: {row.name}: {row.detail}")
    return 1 if failed else 0
