"""Formal figures: how many properties are proven, how deep the others are checked, and that
every cover of their subjects is reached.

The full depths take longer than the rest of the bench together, so they are ``make formal``'s:
the ``formal.*`` figures are read from its last whole run (``build/formal/results.json``), and
say so in their source; with no such run they are left out. The bench itself runs every property
that has a suite depth at that depth (BMC, as ``python -m flow formal --quick``) and gives the
same counts as ``formal.suite_depth.*``: a different measure (shallower), under names of its own.
"""

import json
import os
import time

from sim.formal.suite import RESULTS, Row, figures, run_all
from sim.harness.paths import build_dir

FULL_SOURCE = "formal: make formal's last whole run (build/formal/results.json, written {when})"
QUICK_SOURCE = "formal: every property with a suite depth, BMC to that depth (sim.formal.suite.run_all(quick=True))"


def run():
    out = {}
    results = build_dir("formal") / RESULTS
    if results.exists():
        rows = [Row(**row) for row in json.loads(results.read_text())]
        when = time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime(os.path.getmtime(results)))
        source = FULL_SOURCE.format(when=when)
        out.update({name: (value, unit, source) for name, (value, unit) in figures(rows).items()})
    quick = figures(run_all(quick=True, jobs=2, log=lambda _text: None))
    out.update({name.replace("formal.", "formal.suite_depth.", 1): (value, unit, QUICK_SOURCE)
                for name, (value, unit) in quick.items()})
    return out


if __name__ == "__main__":
    for name, (value, unit, source) in run().items():
        print(f"{name} = {value:g} {unit}  ({source})")
