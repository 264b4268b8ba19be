"""Every formal property of the design, run together: ``make formal``, its bench figures and the
README's table.

A row is one property of one block: a SymbiYosys check (:mod:`sim.formal.block_properties`,
:mod:`sim.formal.store_properties`), proven by k-induction or checked by BMC to a depth, or the structural
proof that no output stream's ``valid`` has a combinational path from a consumer's ``ready``
(:func:`sim.formal.stream_properties.ready_paths`, one per block with stream ports).
"""

import concurrent.futures
import multiprocessing
import subprocess
import time
from dataclasses import dataclass, field

from sim.harness.paths import build_dir, slug

from . import block_properties as blocks
from . import sequencer_properties as sequencer
from . import store_properties as store
from .harness import run
from .stream_properties import ready_paths

__all__ = ["checks", "Row", "run_all", "figures", "RESULTS"]

#: Where a whole ``make formal`` run leaves its rows, in ``build/formal`` (quick or partial runs
#: write beside it): the rows the bench and ``docs/formal.md`` quote.
RESULTS = "results.json"


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
    #: each cover's message -> the first step it is reached at (``None``: not reached); empty
    #: for a structural proof, which holds in every state and has no event to reach
    covers: dict = field(default_factory=dict)

    @property
    def cover_step(self):
        """The step at which the last of the row's covers is first reached."""
        steps = [step for step in self.covers.values() if step is not None]
        return max(steps) if steps else None

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


def _check_row(index, quick):
    """Row of the ``index``-th check (by index: checks build their tops from closures, which do
    not cross to a worker process)."""
    check = checks()[index]
    start = time.monotonic()
    try:
        result = run(check, depth=check.quick if quick else None, prove=not quick, raise_on_failure=False)
    except subprocess.TimeoutExpired as timeout:
        # a check that does not end in its time is a failed row, and the run goes on to the others
        return Row(check.block, check.name, "failed", "BMC", check.depth, time.monotonic() - start,
                   f"SymbiYosys did not end within {timeout.timeout:.0f} s")
    method = "k-induction" if result.status == "proven" else "BMC"
    detail = "" if result.status != "failed" else \
        f"step {result.step}: {'; '.join(result.failed)} (counterexample {result.vcd})"
    return Row(check.block, check.name, result.status, method, result.depth, result.seconds, detail,
               result.covers)


def run_all(*, quick=False, only=None, log=print, jobs=1):
    """Run every check (``quick``: BMC to each check's suite depth, no proofs, the deep checks
    left out) and the structural proofs, ``jobs`` checks at a time; ``only``: block names.
    Returns the rows, in the checks' order."""
    chosen = [i for i, check in enumerate(checks())
              if (not only or check.block in only) and not (quick and check.quick is None)]
    rows = {}
    if jobs > 1:
        context = multiprocessing.get_context("spawn")
        with concurrent.futures.ProcessPoolExecutor(jobs, mp_context=context) as pool:
            futures = {pool.submit(_check_row, i, quick): i for i in chosen}
            for future in concurrent.futures.as_completed(futures):
                rows[futures[future]] = row = future.result()
                log(_line(row))
    else:
        for i in chosen:
            rows[i] = row = _check_row(i, quick)
            log(_line(row))
    rows = [rows[i] for i in chosen]
    for block in blocks.STREAM_BLOCKS:
        if only and block.name not in only:
            continue
        rows.append(_ready_row(block))
        log(_line(rows[-1]))
    return rows


def _line(row):
    covers = f"covers by step {row.cover_step}" if row.cover_step is not None else ""
    return f"{row.block:<17} {row.name:<45} {row.describe():<40} {covers:<20} {row.seconds:7.1f} s"


def figures(rows):
    """``formal.properties_proven``: rows proven (k-induction or structural);
    ``formal.properties_bmc_depth_min``: the shallowest BMC depth among the rest;
    ``formal.properties_without_cover``: SymbiYosys rows with no cover of their subject;
    ``formal.covers_unreached``: covers not reached at their row's depth (each fails its row)."""
    bmc = [row.depth for row in rows if row.method == "BMC" and row.status == "checked"]
    solver = [row for row in rows if row.method != "structural"]
    return {
        "formal.properties_without_cover": (sum(not row.covers for row in solver), "properties"),
        "formal.covers_unreached": (sum(step is None for row in solver for step in row.covers.values()), "covers"),
        "formal.properties_bmc": (sum(row.status == "checked" for row in rows), "properties"),
        "formal.properties_proven": (sum(row.status == "proven" for row in rows), "properties"),
        "formal.properties_bmc_depth_min": (min(bmc) if bmc else 0, "steps"),
        "formal.properties_failed": (sum(row.status == "failed" for row in rows), "properties"),
        "formal.seconds": (sum(row.seconds for row in rows), "s"),
    }
