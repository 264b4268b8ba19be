"""``make bench``: run every benchmark, add the resource figures, write ``build/bench.json``.

``build/bench.json`` is one flat JSON object: ``{"<figure>": {"value": number, "unit": "..."}}``.
The same figures are printed as a table.
"""

import importlib
import json
import math
import time
from pathlib import Path

__all__ = ["collect", "write", "print_table", "main"]


def collect(modules=None, *, resources=True, log=print):
    from sim.bench import MODULES
    figures = {}
    for name in modules or MODULES:
        start = time.monotonic()
        log(f"bench: {name} ...")
        result = importlib.import_module(name).run()
        for key, (value, unit) in result.items():
            if not isinstance(value, (int, float)) or (isinstance(value, float) and not math.isfinite(value)):
                raise ValueError(f"{name}: figure {key} is not a finite number: {value!r}")
            figures[key] = {"value": value, "unit": unit}
        log(f"bench: {name} done in {time.monotonic() - start:.1f} s")
    if resources:
        from flow import resources as res
        log("bench: resources (yosys synth_xilinx -family xc6s) ...")
        for key, (value, unit) in res.figures(res.report()).items():
            figures[key] = {"value": value, "unit": unit}
        from flow import timing
        log("bench: logic depth per clock domain (yosys synth_xilinx -family xc6s) ...")
        for key, (value, unit) in timing.figures(timing.report()).items():
            figures[key] = {"value": value, "unit": unit}
    return figures


def write(figures, path="build/bench.json"):
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(figures, indent=2, sort_keys=True) + "\n")
    return path


def print_table(figures):
    width = max(len(k) for k in figures)
    for key in sorted(figures):
        value, unit = figures[key]["value"], figures[key]["unit"]
        text = f"{value:.6g}" if isinstance(value, float) else str(value)
        print(f"{key:<{width}}  {text:>14}  {unit}")


def main(modules=None, resources=True):
    figures = collect(modules, resources=resources)
    path = write(figures)
    print_table(figures)
    print(f"wrote {path}")
    return 0
