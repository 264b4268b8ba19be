"""Formal figures: how many properties are proven, and how deep the others are checked.

Runs every property of :mod:`sim.formal.suite` at its full depth (as ``make formal`` does):
``formal.properties_proven`` counts the properties proven for every reachable state (k-induction,
or structurally), ``formal.properties_bmc_depth_min`` is the shallowest depth any other property
is checked to; ``formal.properties_without_cover`` and ``formal.covers_unreached`` must be 0.
"""

from sim.formal.suite import figures, run_all


def run():
    return figures(run_all(jobs=2))


if __name__ == "__main__":
    for name, (value, unit) in run().items():
        print(f"{name} = {value:g} {unit}")
