"""How far the projector's register check is from the schedule it must keep.

The parser drops a sequencer record that fails :func:`spec.records.register_faults` (the host
refuses it first, by the same function). Whether a register set it accepts can be played with no
pulse late is the schedule model's to say (:func:`spec.schedule.on_time`). This benchmark draws
register sets around the plan finder's plans (every reset mode, both plane orders, an LSB from
``t_rst + t_settle`` up to past the plan's, a hide threshold from none to every plane) and
counts both ways the check can be wrong:

* ``registers.accepted_late_fraction_model``: of the sets the check accepts, the fraction the
  model plays with a pulse late (the check is not sound for them: the frame would show wrong
  levels, and only ``pulses_late`` would tell);
* ``registers.playable_refused_fraction_model``: of the sets the model plays on time, the
  fraction the check refuses (how conservative it is).

Each is also counted for the global mode alone (``..._global_model``), where the check is meant
to be sound (its accepted-late fraction 0), and for the phased modes (``..._phased_model``),
where the groups' loads share the bus and the check only holds each group to what it needs on
its own.

``python -m sim.bench.registers_figures`` prints them.
"""

import dataclasses
import random

from spec import records, schedule
from spec.facts import TEST_DMD
from spec.registers import PlaneOrder, ResetMode

__all__ = ["run", "draw"]

#: Register sets drawn, and the seed of the draw.
DRAWS, SEED = 200, 1
SOURCE = ("model: {draws} register sets drawn (seed {seed}) around the plan finder's plans on the test DMD at "
          "200 MHz; accepted or refused by spec.records.register_faults, on time or late by spec.schedule.on_time")


def draw(rng, dmd, dclk_hz=200e6):
    """One register set (:class:`spec.schedule.Params`) near a plan the finder makes."""
    plan = schedule.plan(dmd, dclk_hz, reset_mode=rng.choice(list(ResetMode)),
                         order=rng.choice([PlaneOrder.MSB_FIRST, PlaneOrder.LSB_FIRST]),
                         t_rst_s=40 / dclk_hz, t_settle_s=60 / dclk_hz)
    p = plan.params
    lsb = 2 * rng.randint((p.t_rst + p.t_settle) // 2, p.lsb // 2 + 40)
    hide = rng.choice([p.hide, 0, 2 * lsb, 4 * lsb, 1 << 20])
    return dataclasses.replace(p, lsb=lsb, hide=hide)


def _fractions(counts, suffix, source):
    """The figures of one share of the draws: ``counts[accepted, late]``."""
    accepted = counts[True, True] + counts[True, False]
    playable = counts[True, False] + counts[False, False]
    return {
        f"registers.drawn{suffix}_model": (sum(counts.values()), "sets", source),
        f"registers.accepted_late_fraction{suffix}_model": (counts[True, True] / accepted if accepted else 0.0, "",
                                                            source),
        f"registers.playable_refused_fraction{suffix}_model": (counts[False, False] / playable if playable else 0.0,
                                                               "", source),
    }


def run(draws=DRAWS, seed=SEED, dmd=TEST_DMD):
    rng = random.Random(seed)
    shares = {share: {(accepted, late): 0 for accepted in (True, False) for late in (True, False)}
              for share in ("", "_global", "_phased")}
    for _ in range(draws):
        p = draw(rng, dmd)
        faults = records.register_faults(records.register_wire(p.registers(dmd)), dmd, p.beats)
        accepted = not any(bool(bad) for bad in faults.values())
        late = not schedule.on_time(dmd, p, schedule.Frame(0, 8))
        for share in ("", "_global" if p.reset_mode == ResetMode.GLOBAL else "_phased"):
            shares[share][accepted, late] += 1
    source = SOURCE.format(draws=draws, seed=seed)
    return {name: figure for share, counts in shares.items() for name, figure in _fractions(counts, share,
                                                                                            source).items()}


if __name__ == "__main__":
    for figure, (value, unit, source) in run().items():
        print(f"{figure:45s} {value:8.3f} {unit:5s} {source}")
