"""Camera model: the image a sensor integrates from the DMD over a window of cycles.

The light a pixel sends to the sensor is its mirror's on-fraction: 0 (off) or 1 (on) between
transitions. A clocking pulse of a block at cycle ``p`` (recorded by
:class:`sim.models.dlpc410_model.Dlpc410` in ``history``, with the state it latched) starts every
mirror of the block that changes moving at ``p + delay_cycles``; the light then ramps linearly
to the new state over ``ramp_cycles`` (a mirror that keeps its state does not move).

Assumption (documented in ``docs/dlpc410_model.md``): the linear ramp stands for the crossover
(DLP7000 7.12: 4 us crossover, 12.5 us typical switching including settling). A linear ramp
makes an on-interval between two transitions integrate to exactly its length however long the
ramp, as long as ramps do not overlap; delay and ramp are parameters.

:meth:`Camera.image` returns the integral in cycles of full-on light per pixel; divided by the
LSB time of a binary-weighted PWM (:func:`to_lsb`) it is the grey level the sensor saw.

Per block the history is piecewise constant, so the integral is a weighted sum of the recorded
states: with ``F(x)`` the integral of the ramp up to ``x``, transition ``i`` (state ``S_i``
replacing ``S_{i-1}``, starting at ``s_i``) adds ``(S_i - S_{i-1}) (F(t1 - s_i) - F(t0 - s_i))``;
summed by parts this is ``sum_i S_i (w_i - w_{i+1})``, one tensordot per block.

The light source: with a ``gate`` (the sequencer's gate pin, its changes as ``(cycle, level)``)
the light is that waveform with the source's rise and fall (linear ramps,
:data:`spec.facts.LIGHT`), multiplied by each pixel's mirror state: ``w_i`` is then the integral
of the light times transition ``i``'s ramp, worked out exactly piece by piece (both are linear
between their breakpoints, so a two-point Gauss rule on each piece is exact). Without one the light is
constant on.
"""

import numpy as np

__all__ = ["Camera", "to_lsb", "ramp_integral", "lit_ramp_integral"]

#: Two-point Gauss-Legendre nodes on a piece (from its middle, in half-widths): exact for the
#: product of two linear pieces, and never on a breakpoint, where a step (a ramp of no length) jumps.
_NODES = (-1 / np.sqrt(3), 1 / np.sqrt(3))


def ramp_integral(x, ramp):
    """Integral from -inf to ``x`` of a ramp from 0 (x <= 0) to 1 (x >= ramp)."""
    x = np.asarray(x, dtype=np.float64)
    if ramp == 0:
        return np.maximum(x, 0.0)
    return np.where(x <= 0, 0.0, np.where(x < ramp, x * x / (2 * ramp), x - ramp / 2))


def _ramp(x, length):
    """A ramp from 0 (x <= 0) to 1 (x >= length); a step at 0 if ``length`` is 0."""
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(length > 0, np.clip(x / np.where(length > 0, length, 1), 0.0, 1.0), x > 0)


def lit_ramp_integral(starts, ramp, edges, rise, fall, t0, t1, initial=0):
    """For each transition start in ``starts`` (an array), the integral over ``[t0, t1)`` of the
    light (the gate's ``edges``, ``(cycle, level)`` changes from ``initial``, ramping up over
    ``rise`` and down over ``fall`` cycles) times the transition's ramp from 0 to 1 over
    ``ramp`` cycles."""
    starts = np.asarray(starts, dtype=np.float64)
    # the light as a sum of ramps: ``initial``, then +1 from each rise, -1 from each fall
    terms = [(e, 1.0, rise) if level else (e, -1.0, fall) for e, level in edges if e < t1]
    out = initial * _ramp_product(starts, ramp, np.array([-np.inf]), np.array([0.0]), t0, t1).sum(axis=1)
    if terms:
        at, sign, length = (np.array(v, dtype=np.float64) for v in zip(*terms, strict=True))
        out += (_ramp_product(starts, ramp, at, length, t0, t1) * sign).sum(axis=1)
    return out


def _ramp_product(starts, ramp, at, length, t0, t1):
    """(starts, edges) integrals over ``[t0, t1)`` of a ramp from each start (over ``ramp``) times
    a ramp from each edge ``at`` (over its ``length``)."""
    s, a, n = starts[:, None, None], at[None, :, None], length[None, :, None]
    with np.errstate(invalid="ignore"):
        knots = np.concatenate(np.broadcast_arrays(np.full_like(s, t0), np.full_like(s, t1), s, s + ramp,
                                                   a + 0 * s, a + n + 0 * s), axis=2)
    knots = np.sort(np.clip(np.nan_to_num(knots, neginf=t0, posinf=t1), t0, t1), axis=2)
    middle, half = (knots[..., 1:] + knots[..., :-1]) / 2, (knots[..., 1:] - knots[..., :-1]) / 2

    def f(x):
        return _ramp(x - s, ramp) * np.where(np.isinf(a), 1.0, _ramp(x - a, n))
    return (half * sum(f(middle + node * half) for node in _NODES)).sum(axis=2)


def to_lsb(image, lsb_cycles):
    """Light in cycles -> grey levels in units of the least significant plane's time."""
    return np.asarray(image, dtype=np.float64) / lsb_cycles


class Camera:
    """Integrates the mirror history of ``model`` (a :class:`~sim.models.dlpc410_model.Dlpc410`
    built with ``keep_history=True``).

    Parameters
    ----------
    model : Dlpc410
    ramp_cycles : int, optional
        Length of the linear transition; default the crossover time (DLP7000 7.12) at the
        model's DCLK.
    delay_cycles : int
        Pulse command to the start of the mirrors' motion.
    visible : bool
        Return only the visible columns (the DLP9500's 1920 of 2048).
    gate : list of (int, int), optional
        The gate pin's changes ``(cycle, level)`` in the model's cycles, low before the first
        (None: the light is constant on).
    rise_cycles, fall_cycles : float
        The light source's rise and fall with a ``gate``.
    """

    def __init__(self, model, *, ramp_cycles=None, delay_cycles=0, visible=True, gate=None, rise_cycles=0,
                 fall_cycles=0):
        self.model = model
        self.gate, self.rise, self.fall = gate, rise_cycles, fall_cycles
        self.ramp = model.timing["crossover_cycles"] if ramp_cycles is None else ramp_cycles
        self.delay = delay_cycles
        self.visible = visible
        self._cache = {}

    def _block_history(self, block):
        hist = self.model.history[block]
        cached = self._cache.get(block)
        if cached is None or cached[0] != len(hist):
            times = np.array([c for c, _ in hist], dtype=np.int64) + self.delay
            states = np.stack([s for _, s in hist]) if hist else None
            cached = self._cache[block] = (len(hist), times, states)
        return cached[1], cached[2]

    def image(self, t0, t1):
        """Light per pixel integrated over cycles ``[t0, t1)``, in cycles (float64)."""
        dmd = self.model.dmd
        rpb = dmd.rows_per_block
        out = np.zeros((dmd.rows, dmd.columns), np.float64)
        for b in range(dmd.blocks):
            times, states = self._block_history(b)
            if states is None:
                continue
            # transitions that have finished before t0 leave only the last one's state;
            # those starting at or after t1 contribute nothing
            first = max(0, int(np.searchsorted(times + self.ramp, t0, side="right")) - 1)
            last = int(np.searchsorted(times, t1, side="left"))
            if last <= first:
                continue
            starts = times[first:last]
            if self.gate is None:
                w = ramp_integral(t1 - starts, self.ramp) - ramp_integral(t0 - starts, self.ramp)
            else:
                w = lit_ramp_integral(starts, self.ramp, self.gate, self.rise, self.fall, t0, t1)
            coef = w - np.append(w[1:], 0.0)
            out[b * rpb:(b + 1) * rpb] = np.tensordot(coef, states[first:last], axes=1)
        return out[:, :dmd.visible_columns] if self.visible else out
