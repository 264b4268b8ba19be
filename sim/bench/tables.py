"""What the benchmarks write beside their figures: a table (CSV) and a plot (PNG) in ``build/``."""

import csv

from sim.harness.paths import build_dir

__all__ = ["write_table", "pyplot", "label", "save_figure"]


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


def label(ax, xlabel, ylabel, title=None, legend_title=None):
    """An axis's labels, title, legend and a light grid."""
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    if title:
        ax.set_title(title)
    ax.legend(title=legend_title)
    ax.grid(True, alpha=0.3)


def save_figure(plt, fig, name):
    """``build/<name>.png``, the figure then closed."""
    fig.tight_layout()
    fig.savefig(build_dir() / f"{name}.png", dpi=100)
    plt.close(fig)
