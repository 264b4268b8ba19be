"""Every formal property of the design, run together: ``make formal``, its bench figures and the
README's table.

A row is one property of one block: a SymbiYosys check (:mod:`sim.formal.blocks`,
:mod:`sim.formal.store`), proven by k-induction or checked by BMC to a depth, or the structural
proof that no output stream's ``valid`` has a combinational path from a consumer's ``ready``
(:func:`sim.formal.streams.ready_paths`, one per block with stream ports).
"""

import time
from dataclasses import dataclass

from sim.harness.paths import build_dir, slug

from . import blocks, sequencer, store
from .harness import run
from .streams import ready_paths

__all__ = ["checks", "Row", "run_all", "figures"]


def checks():
    return [*blocks.checks(), *store.store_checks(), *sequencer.sequencer_checks()]


@dataclass
class Row:
    block: str
    name: str
    status: str          # "proven", "checked", "failed"
    method: str          # "k-induction", "BMC", "structural"
    depth: int | None
    seconds: float
    detail: str = ""

    def describe(self):
        if self.status == "failed":
            return f"FAILED: {self.detail}"
        if self.method == "structural":
            return "proven (structural, all states)"
        if self.status == "proven":
            return f"proven, k-induction depth {self.depth}"
        return f"checked to depth {self.depth} (BMC)"


def _ready_row(block):
    start = time.monotonic()
    found = ready_paths(block.make(), build_dir("formal", slug(f"{block.name}-ready")))
    detail = "; ".join(f"{valid} from {', '.join(readies)}" for valid, readies in found.items())
    return Row(block.name, "valid independent of ready", "failed" if found else "proven", "structural", None,
               time.monotonic() - start, detail)


def run_all(*, quick=False, only=None, log=print):
    """Run every check (``quick``: BMC to each check's test depth, no proofs) and the structural
    proofs; ``only``: block names. Returns the rows."""
    rows = []
    for check in checks():
        if only and check.block not in only:
            continue
        result = run(check, depth=check.quick if quick else None, prove=not quick, raise_on_failure=False)
        method = "k-induction" if result.status == "proven" else "BMC"
        detail = "" if result.status != "failed" else \
            f"step {result.step}: {'; '.join(result.failed)} (counterexample {result.vcd})"
        rows.append(Row(check.block, check.name, result.status, method, result.depth, result.seconds, detail))
        log(_line(rows[-1]))
    for block in blocks.STREAM_BLOCKS:
        if only and block.name not in only:
            continue
        rows.append(_ready_row(block))
        log(_line(rows[-1]))
    return rows


def _line(row):
    return f"{row.block:<17} {row.name:<45} {row.describe():<40} {row.seconds:7.1f} s"


def figures(rows):
    """``formal.properties_proven``: rows proven (k-induction or structural);
    ``formal.properties_bmc_depth_min``: the shallowest BMC depth among the rest."""
    bmc = [row.depth for row in rows if row.method == "BMC" and row.status == "checked"]
    return {
        "formal.properties_proven": (sum(row.status == "proven" for row in rows), "properties"),
        "formal.properties_bmc_depth_min": (min(bmc) if bmc else 0, "steps"),
        "formal.properties_failed": (sum(row.status == "failed" for row in rows), "properties"),
        "formal.seconds": (sum(row.seconds for row in rows), "s"),
    }
