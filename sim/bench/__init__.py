"""Benchmarks: each module here has ``run() -> {figure name: (value, unit, source)}``.

``make bench`` (``python -m flow bench``) runs every module listed in :data:`MODULES` (each named
``<subject>_figures``; ``tables`` and ``rig_rate`` serve them), adds the resource figures and writes
``build/bench.json``. Figures are measured, never written down: each comes from a simulation or a
synthesis run made by the benchmark itself. Each records where it comes from (``source``: its first
word the kind, ``gateware``, ``model``, ``arithmetic``, ...: :mod:`flow.bench`); a module whose
figures share one source may give ``(value, unit)`` and say it once in ``SOURCE``. A figure whose
kind is ``model`` (or arithmetic on one) has ``_model`` in its name.
"""

MODULES = [
    "sim.bench.bitplane_figures",
    "sim.bench.bounds_figures",
    "sim.bench.camera_figures",
    "sim.bench.dlpc410_model_figures",
    "sim.bench.dual_figures",
    "sim.bench.formal_figures",
    "sim.bench.gated_figures",
    "sim.bench.host_figures",
    "sim.bench.mac_figures",
    "sim.bench.net_figures",
    "sim.bench.pcs_figures",
    "sim.bench.rates_figures",
    "sim.bench.registers_figures",
    "sim.bench.store_figures",
    "sim.bench.sync_figures",
    "sim.bench.seq_figures",
    "sim.bench.seq_rig_figures",
    "sim.bench.system_figures",
    "sim.bench.system_xga_figures",
]
