"""Frame-rate bounds past one DMD's PWM (:mod:`spec.bounds`, ``docs/bounds.md`` "Beyond one DMD").

For the DLP7000 and the DLP9500 at DCLK 400 MHz, at the bus's pace (a row every row cycle) and the
memory's (a row every ``row_period`` cycles, the row period :func:`spec.schedule.plan` takes at
the read rate the memory leaves the plane reader under GigE ingest,
:func:`sim.rigs.fast_system_rig.read_rate`, as ``make sim`` plans; the SVEC's DDR3 assumed to
give the DLP9500 what the Atlys's DDR2 gives, as ``constraints/README.md`` does):

* ``bounds.<scheme>_gray<n>_hz_<dmd>_<pace>_model``: each scheme of :data:`spec.bounds.SCHEMES`;
* ``bounds.dual_gray<n>_low_bits_model``: the two-DMD split's low bits;
* ``bounds.gated_gray<n>_lsb_cycles_<dmd>_<pace>_model``: a gated frame's least significant light;
* ``bounds.sequence_frames_gray<n>_<dmd>_<memory>_model``: frames of ``n`` planes a memory holds;
* ``bounds.one_gray8_shipped_fraction_dlp7000_memory_model``: the shipped plan's rate over its bound;
* ``bounds.anchor_<name>_hz``: the rates of :data:`spec.facts.ANCHORS`, as their documents state them.

``python -m sim.bench.bounds_figures`` prints them.
"""

from spec import bounds, schedule
from spec.facts import ANCHORS, DMDS

__all__ = ["run", "DEPTHS", "DCLK_HZ", "row_periods"]

#: The depths the figures are given at.
DEPTHS = (1, 8, 10, 12, 16)
DCLK_HZ = 400e6
DMD_NAMES = ("dlp7000", "dlp9500")
SOURCE = "model: spec.bounds.{fn} ({what}), the facts table's timing, {dmd} at DCLK 400 MHz, {pace}"


def row_periods():
    """The memory's row period of each DMD: the plan's at the read rate under GigE ingest."""
    from sim.models.mcb_model import McbTiming
    from sim.rigs.fast_system_rig import read_rate
    words = read_rate(McbTiming(), schedule.FABRIC_HZ)
    return {name: schedule.plan(DMDS[name], DCLK_HZ, depth=1, chain=True, words_per_cycle=words).params.row_period
            for name in DMD_NAMES}


def _rates(name, pace, paces):
    text = "a row every row cycle" if pace == "bus" else \
        f"a row every {paces.row_period} cycles (bounds.row_period_cycles_{name}_memory_model)"
    out = {}
    for depth in DEPTHS:
        for scheme, fn in bounds.SCHEMES.items():
            b = fn(paces, depth)
            what = f"{depth} bits, binds {b.binds}" + (f", low bits {b.k}" if b.k is not None else "")
            source = SOURCE.format(fn=fn.__name__, what=what, dmd=name, pace=text)
            out[f"bounds.{scheme}_gray{depth}_hz_{name}_{pace}_model"] = (b.rate_hz, "Hz", source)
            if scheme == "gated":
                out[f"bounds.gated_gray{depth}_lsb_cycles_{name}_{pace}_model"] = (b.lsb, "cycle", source)
            if scheme == "dual" and name == DMD_NAMES[0] and pace == "bus":
                out[f"bounds.dual_gray{depth}_low_bits_model"] = (b.k, "bit", source)
    return out


def run():
    from sim.rigs import xga_run
    figures = {}
    periods = row_periods()
    for name in DMD_NAMES:
        dmd = DMDS[name]
        figures[f"bounds.row_period_cycles_{name}_memory_model"] = (
            periods[name], "cycle", "model: spec.schedule.plan's row period at the MCB timing model's read rate "
                                    "under GigE ingest (sim.rigs.fast_system_rig.read_rate)")
        for pace, period in (("bus", None), ("memory", periods[name])):
            figures.update(_rates(name, pace, bounds.Paces.of(dmd, DCLK_HZ, period)))
        for depth in DEPTHS:
            for memory in bounds.MEMORIES:
                figures[f"bounds.sequence_frames_gray{depth}_{name}_{memory}_model"] = (
                    bounds.sequence_frames(dmd, depth, memory), "frame",
                    f"model: spec.bounds.sequence_frames, {depth} planes a frame in {memory} "
                    f"(spec.facts.MEMORY), the store's plane layout")
    xga = bounds.Paces.of(DMDS["dlp7000"], DCLK_HZ)
    for depth, lead, shortest in ((16, "switch", "cycle"), (12, "settle", "edges"), (16, "settle", "edges")):
        b = bounds.gated(xga, depth, lead=lead, shortest=shortest)
        tail = "_switch_lead" if lead == "switch" else "_edge_pulses"
        figures[f"bounds.gated_gray{depth}_hz_dlp7000_bus{tail}_model"] = (
            b.rate_hz, "Hz", f"model: spec.bounds.gated, {depth} bits, the lead {lead}, the shortest light pulse "
                             f"{shortest} (spec.bounds.LEADS, SHORTEST), DLP7000 at DCLK 400 MHz, a row every row "
                             f"cycle, binds {b.binds}")
    shipped = xga_run.plan(DCLK_HZ)
    assert shipped.params.row_period == periods["dlp7000"]
    bound = bounds.one(bounds.Paces.of(DMDS["dlp7000"], DCLK_HZ, periods["dlp7000"]), 8)
    figures["bounds.one_gray8_shipped_fraction_dlp7000_memory_model"] = (
        shipped.rate_hz / bound.rate_hz, "", "model: the rate of the shipped plan (sim.rigs.xga_run.plan, the schedule "
                                             "model's period) over bounds.one_gray8_hz_dlp7000_memory_model")
    for key, fact in ANCHORS.items():
        figures[f"bounds.anchor_{key}_hz"] = (fact.value, fact.unit,
                                              f"document: {fact.source}, {fact.note} (spec.facts.ANCHORS)")
    return figures


if __name__ == "__main__":
    for key, (value, unit, source) in sorted(run().items()):
        print(f"{key:<62} {value:>12.6g} {unit:<6} {source}")
