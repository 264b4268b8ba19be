"""Benchmarks: each module here has ``run() -> {figure name: (value, unit, source)}``.

``make bench`` (``python -m flow bench``) runs every module listed in :data:`MODULES`, adds
the resource figures and writes ``build/bench.json``. Figures are measured, never written down:
each comes from a simulation or a synthesis run made by the benchmark itself. Each records where
it comes from (``source``: its first word the kind, ``gateware``, ``model``, ``arithmetic``, ...:
:mod:`flow.bench`); a module whose figures share one source may give ``(value, unit)`` and say it
once in ``SOURCE``. A figure whose kind is ``model`` (or arithmetic on one) has ``_model`` in its
name.
"""

MODULES = [
    "sim.bench.bitplane",
    "sim.bench.camera",
    "sim.bench.dlpc410_model",
    "sim.bench.formal",
    "sim.bench.host",
    "sim.bench.mac",
    "sim.bench.net",
    "sim.bench.rates",
    "sim.bench.registers",
    "sim.bench.store",
    "sim.bench.sync",
    "sim.bench.seq",
    "sim.bench.seq_rig",
    "sim.bench.system",
    "sim.bench.system_xga",
]
