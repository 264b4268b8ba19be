"""What the benchmarks write beside their figures: a table (CSV) and a plot (PNG) in ``build/``."""

import csv

from sim.harness.paths import build_dir

__all__ = ["write_table", "pyplot"]


def write_table(name, header, rows):
    """``build/<name>.csv`` with ``header`` and ``rows``; returns its path."""
    path = build_dir() / f"{name}.csv"
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(header)
        w.writerows(rows)
    return path


def pyplot():
    """matplotlib's pyplot, drawing to files only (no display needed)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt
