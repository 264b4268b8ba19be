"""Formal checks of Amaranth components with SymbiYosys: a top around the component, its
properties in Amaranth, the ``.sby`` file, the run and its verdict.

A :class:`Check` names a property, the block it is about and how to build the formal top: an
Amaranth elaboratable whose ``Assert`` statements are the property and whose ``Assume``
statements are the environment. :class:`FormalTop` is the usual top: the component with every
input port free (``AnySeq``), the domains' resets held low (the design starts from its power-up
state), and property functions ``f(m, top)`` that add the statements.

:func:`run` converts the top to RTLIL, writes ``<name>.sby`` (mode ``prove``: k-induction with
the smtbmc engine and Yices; or ``bmc`` to a depth), runs SymbiYosys with the shims of
:mod:`sim.formal.tools` and returns a :class:`Result`: proven (k-induction at depth k) or
checked to depth N. A failing check raises :class:`FormalFailure` with the counterexample's VCD.
A check whose induction does not close at its depth is checked by BMC to ``bmc_depth`` instead,
and says so.

A top in more than one domain runs on one formal clock: each domain's registers (and memory
ports) take a step only when that domain's enable, free at every step, is high
(:class:`~amaranth.hdl.EnableInserter`); a clock pauses for at most ``max_pause - 1`` steps in
a row, so the clocks keep no fixed ratio but none runs more than ``max_pause`` times as fast as
another (2 by default: the design's clocks are 125 and 200 MHz). A depth counts steps of the
fastest clock. Inputs of such a top change only at their domain's cycles.
"""

import re
import subprocess
import time
from dataclasses import dataclass, field
from pathlib import Path

from amaranth import (
    ClockDomain,
    ClockSignal,
    DomainRenamer,
    Elaboratable,
    EnableInserter,
    Module,
    Mux,
    ResetSignal,
    Signal,
)
from amaranth.asserts import AnySeq
from amaranth.back import rtlil
from amaranth.hdl import Assume
from amaranth.lib import wiring

from sim.harness.paths import build_dir, slug

from .tools import environment

__all__ = ["Check", "Result", "FormalFailure", "FormalTop", "run", "reach", "covered", "sby_text"]


class FormalFailure(AssertionError):
    """A property failed: ``result.vcd`` is the counterexample, ``result.failed`` the asserts."""

    def __init__(self, result):
        self.result = result
        where = "\n  ".join(result.failed) or "(see the log)"
        super().__init__(f"{result.check.block}: {result.check.name}: {result.status} at step "
                         f"{result.step}\n  {where}\ncounterexample: {result.vcd}\nlog: {result.log}")


@dataclass(frozen=True)
class Check:
    """One property of one block.

    Parameters
    ----------
    name : str
        The property, as the README lists it.
    block : str
        The block (class) it is about.
    build : callable
        ``build() -> Elaboratable``: the formal top.
    depth : int
        BMC depth (steps) for ``make formal``.
    induction : int or None
        k for a k-induction proof; None when induction does not close (BMC only).
    quick : int or None
        Depth for the test suite, at least the step its covers are reached at; None: a deep
        check, run by ``make formal`` only (which ``.ci/run`` runs).
    quick_proof : bool
        The suite tries the k-induction proof too (False: a costly proof, BMC to ``quick``).
    """
    name: str
    block: str
    build: object
    depth: int
    induction: int | None = None
    quick: int | None = 10
    quick_proof: bool = True

    @property
    def key(self):
        return slug(f"{self.block}-{self.name}")


@dataclass
class Result:
    check: Check
    status: str                  # "proven", "checked", "failed"
    depth: int                   # k of the proof, or the BMC depth reached
    seconds: float
    log: Path
    vcd: Path | None = None
    step: int | None = None
    failed: list = field(default_factory=list)
    induction_failed: bool = False
    #: each cover's message -> the first step it is reached at (``None``: not reached)
    covers: dict = field(default_factory=dict)

    @property
    def unreached(self):
        return sorted(k for k, v in self.covers.items() if v is None)

    def describe(self):
        if self.status == "proven":
            return f"proven, k-induction depth {self.depth}"
        if self.status == "checked":
            return f"checked to depth {self.depth}"
        return f"FAILED at step {self.step}"


class FormalTop(Elaboratable):
    """A component with free inputs and its properties.

    Parameters
    ----------
    dut : wiring.Component
    properties : iterable of callables ``f(m, top)``
        Each adds statements about ``top.dut`` to ``m``.
    domains : iterable of str
        Clock domains the component uses (each gets a clock, and a reset held low).
    port_domains : dict
        Top-level port name -> its domain (default ``sync``); with more than one domain, free
        inputs change only at their domain's clock edges.
    driven : iterable of str
        Top-level ports the properties drive themselves (not left free).
    max_pause : int
        With several domains: a domain's clock never pauses for ``max_pause`` formal steps in a
        row, so any two clocks are within a ratio of ``max_pause`` to one.
    body : Elaboratable or None
        ``dut`` already elaborated (its ``elaborate``'s module), for properties about parts the
        component makes while it is elaborated; default: ``dut`` itself.
    """

    def __init__(self, dut, properties=(), *, domains=("sync",), port_domains=None, driven=(), max_pause=2,
                 body=None):
        self.dut = dut
        self.body = dut if body is None else body
        self.max_pause = max_pause
        self.driven = set(driven)
        self.properties = list(properties)
        self.domains = tuple(domains)
        self.port_domains = dict(port_domains or {})

    def domain_of(self, path):
        return self.port_domains.get(path[0], "sync")

    def elaborate(self, platform):
        m = Module()
        dut = self.dut
        m.submodules.dut = self.body
        ticked = len(self.domains) > 1
        for name in self.domains:
            m.d.comb += Assume(~ResetSignal(name))
        for path, member, value in dut.signature.flatten(dut):
            if member.flow != wiring.In or path[0] in self.driven:
                continue
            value = value.as_value() if hasattr(value, "as_value") else value
            if not isinstance(value, Signal):
                continue                     # a constant (an always-ready stream's ready)
            if ticked:
                held = Signal.like(value, name="free__" + "__".join(map(str, path)))
                m.d[self.domain_of(path)] += held.eq(AnySeq(len(value)))
                m.d.comb += value.eq(held)
            else:
                m.d.comb += value.eq(AnySeq(len(value)))
        for prop in self.properties:
            prop(m, self)

        # One clock for SymbiYosys; each domain's cycles happen at the steps its enable chooses.
        outer = Module()
        outer.domains.sync = ClockDomain("sync")
        inner = m
        if ticked:
            ticks = {name: Signal(name=f"tick_{name}") for name in self.domains}
            for name, tick in ticks.items():
                # a domain's clock may pause, but for fewer than ``max_pause`` steps in a row
                paused = Signal(range(self.max_pause + 1), name=f"paused_{name}")
                outer.d.sync += paused.eq(Mux(tick, 0, paused + 1))
                outer.d.comb += [tick.eq(AnySeq(1)), Assume(tick | (paused + 1 < self.max_pause))]
            inner = EnableInserter(ticks)(inner)
        outer.submodules.top = DomainRenamer({name: "sync" for name in self.domains if name != "sync"})(inner)
        return outer


def sby_text(check, *, mode, depth):
    """The ``.sby`` file of a check. A cover run writes no VCD: only the step each cover is
    reached at is read, and writing a deep trace costs more than finding it."""
    return "\n".join([
        "[options]",
        f"mode {mode}",
        f"depth {depth}",
        *(["vcd off"] if mode == "cover" else []),
        "",
        "[engines]",
        "smtbmc yices",
        "",
        "[script]",
        "read_rtlil top.il",
        "prep -flatten -top top",
        "",
        "[files]",
        "top.il",
        "",
    ])


def _convert(check, folder):
    top = check.build()
    text = rtlil.convert(top, name="top", ports=[ClockSignal("sync")])
    path = folder / "top.il"
    path.write_text(text)
    return path


_COVER = re.compile(r"(Reached|Unreached) cover statement (?:in step (\d+) )?at .*\(_witness_\.(\w+)\)")
_FAILED = re.compile(r"(Assert failed in .*|Assumptions are unsatisfiable.*)$")
_STEP = re.compile(r"BMC failed!|Checking assertions in step (\d+)")


def _sby(folder, check, mode, depth, timeout, allow_fail=False):
    """Run SymbiYosys on ``check`` in ``folder/<mode>``; returns (status, workdir, log text)."""
    sby = folder / f"{mode}.sby"
    sby.write_text(sby_text(check, mode=mode, depth=depth))
    workdir = folder / mode
    proc = subprocess.run(["sby", "-f", str(sby.name)], cwd=folder, env=environment(),
                          capture_output=True, text=True, timeout=timeout)
    status_file = workdir / "status"
    status = status_file.read_text().split()[0] if status_file.exists() else "ERROR"
    log = (workdir / "logfile.txt")
    text = log.read_text() if log.exists() else proc.stdout + proc.stderr
    if status == "ERROR" or (status == "FAIL" and mode == "cover" and not allow_fail):
        raise RuntimeError(f"SymbiYosys could not run {check.block}: {check.name}:\n{text[-3000:]}")
    return status, workdir, text


def _messages(folder):
    """Witness name of each ``Assert`` (``check_<n>`` in the top module, or
    ``check_flatten_<instance path>__<n>`` once flattened) -> its message."""
    messages = {}
    module = cell = None
    for line in (folder / "top.il").read_text().splitlines():
        if line.startswith("module "):
            module = line.split()[1].lstrip("\\").split(".")[1:]
        elif line.lstrip().startswith("cell "):
            match = re.match(r"\s*cell \$check \$(\d+)", line)
            cell = match and match.group(1)
        elif cell and (match := re.match(r'\s*parameter \\FORMAT "([^"]*)"', line)):
            prefix = "check_flatten_" + "_".join(module) + "__" if module else "check_"
            messages[prefix + cell] = match.group(1)
    return messages


def _failure(check, workdir, text, seconds, depth):
    messages = _messages(workdir.parent)
    failed = set()
    for line in text.splitlines():
        if match := _FAILED.search(line):
            witness = re.search(r"_witness_\.(check_\w+)", line)
            failed.add(messages.get(witness.group(1), match.group(1)) if witness else match.group(1).strip())
    failed = sorted(failed)
    steps = [int(m.group(1)) for line in text.splitlines()
             if (m := re.search(r"Checking assertions in step (\d+)", line))]
    traces = sorted(workdir.glob("engine_*/trace*.vcd"))
    return Result(check, "failed", depth, seconds, workdir / "logfile.txt",
                  vcd=traces[0] if traces else None, step=steps[-1] if steps else None, failed=failed)


def run(check, *, depth=None, prove=True, timeout=3600, raise_on_failure=True, covers=True):
    """Run ``check``: a k-induction proof when it has one (and ``prove``), else BMC to ``depth``
    (default ``check.depth``); then (``covers``) its covers to the same depth. A cover not
    reached within that depth fails the check: the property never met its subject."""
    folder = build_dir("formal", check.key)
    start = time.monotonic()
    _convert(check, folder)
    depth = check.depth if depth is None else depth
    induction_failed = False
    result = None
    if prove and check.induction is not None:
        status, workdir, text = _sby(folder, check, "prove", check.induction, timeout)
        if status == "PASS":
            result = Result(check, "proven", check.induction, time.monotonic() - start, workdir / "logfile.txt")
        elif status == "FAIL" and "Temporal induction failed" not in text.split("summary")[-1]:
            result = _failure(check, workdir, text, time.monotonic() - start, check.induction)
        else:
            induction_failed = True
    if result is None:
        status, workdir, text = _sby(folder, check, "bmc", depth, timeout)
        seconds = time.monotonic() - start
        if status == "PASS":
            result = Result(check, "checked", depth, seconds, workdir / "logfile.txt",
                            induction_failed=induction_failed)
        else:
            result = _failure(check, workdir, text, seconds, depth)
    if covers and result.status != "failed":
        reached, unreached = covered(check, depth, timeout=timeout)
        result.covers = {**reached, **dict.fromkeys(unreached)}
        if not result.covers:
            # a property must come with a cover of the event it is about
            result.status = "failed"
            result.failed = ["no cover of the property's subject"]
        elif unreached:
            result.status = "failed"
            result.failed = [f"cover not reached within {depth} steps: {message}" for message in unreached]
    if result.status == "failed" and raise_on_failure:
        raise FormalFailure(result)
    return result


def reach(check, depth, *, timeout=3600):
    """The first step at which each ``Cover`` of ``check`` is reached within ``depth`` steps:
    ``{message: step}``, ``None`` for a cover not reached. SymbiYosys stops as soon as every
    cover is reached, so a deep ``depth`` costs only what the last cover needs."""
    folder = build_dir("formal", check.key)
    _convert(check, folder)
    _status, _workdir, text = _sby(folder, check, "cover", depth, timeout, allow_fail=True)
    messages = _messages(folder)
    reached = {}
    for line in text.splitlines():
        if match := _COVER.search(line):
            kind, step, witness = match.groups()
            message = messages.get(witness, witness)
            if kind == "Reached":
                step = int(step)
                reached[message] = step if reached.get(message) is None else min(reached[message], step)
            else:
                reached.setdefault(message, None)
    return reached


def covered(check, depth, *, timeout=3600):
    """Run ``check``'s covers to ``depth``; returns ``(reached, unreached)``: ``{message: step}``
    and the messages of covers not reached."""
    reached = reach(check, depth, timeout=timeout)
    return ({k: v for k, v in reached.items() if v is not None},
            sorted(k for k, v in reached.items() if v is None))
