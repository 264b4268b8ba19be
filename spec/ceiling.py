"""The ceiling of one-timeline plans: the fastest 8-bit rate any plan of the kind the sequencer
plays can reach, whatever its plane order, LSB and stagger (derivation: ``docs/bounds.md``).

The sequencer plays one timeline for every group: one plane order, one LSB and hide threshold,
group ``g`` ``g * stagger`` behind group 0, and the next frame only once the last group is loaded
again. :func:`spec.schedule.bound` leaves out what this costs; here each cost is counted at its
least, with the loads assumed free:

* a plane of ``L`` cycles hides its successor's load only if ``L >= reload`` (``t_rst +
  t_settle`` frozen, then the group's rows at the full row rate); a shorter one, and a frame's
  last plane, ends in a dark pulse ``L`` after its pulse, and the next plane comes ``reload``
  after the dark pulse at the earliest;
* the LSB is at least ``t_rst + t_settle`` and the group's block clears (the settle path);
* the pulses of two groups are at least ``sep`` apart: ``t_rst`` under TI's (strict) RST_ACTIVE
  reading, a row cycle under the loose one; the stagger is the smallest even one that keeps
  every multiple ``k * stagger`` (``0 < k < G``) that far from every difference of the
  timeline's pulse times;
* a frame lasts until the last group's last dark pulse and its reload of the next frame's
  first plane: ``(G - 1) * stagger + T + reload`` (``T``: the last dark pulse's time).

Every plane order (all ``depth!``) and every LSB from the settle path up is tried, up to the
LSB at which ``(2**depth - 1) * LSB + reload + (G - 1) * sep`` alone passes the best frame found
(no longer LSB can beat it). The timing is the facts table's, without the sequencer's margins, so the sequencer
can reach no more than this (TI's settle reading; triggered frames, each ending dark).
"""

import itertools
import math
import os
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass

import numpy as np

from .facts import TIMING
from .registers import ResetMode
from .schedule import FABRIC_HZ, beats_at, even, groups, row_cycles, timeline

__all__ = ["Ceiling", "ceiling", "ceiling_of_mode", "facts_cycles"]


@dataclass(frozen=True)
class Ceiling:
    """The fastest one-timeline plan of a reset mode: its frame, plane order (weight exponents
    in display order), LSB and stagger, in ``dmd`` cycles."""
    reset_mode: ResetMode
    frame_cycles: int
    order: tuple
    lsb: int
    stagger: int

    @property
    def rate_hz(self):
        return FABRIC_HZ / self.frame_cycles


def _stagger(pulses, G, sep, limit):
    """The smallest even stagger from ``sep`` on that keeps every pulse of group ``g`` at least
    ``sep`` from every pulse of group ``h`` (``g * stagger`` apart), or None past ``limit``."""
    d = np.unique(pulses[:, None] - pulses[None, :])[None, :]
    k = np.arange(1, G)[:, None]
    # k * s must not fall in (-d - sep, sep - d) for a difference d: s in (lo, hi) is ruled out
    keep = np.broadcast_to(sep - d > k * sep, (G - 1, d.shape[1]))
    ks, ds = np.broadcast_to(k, keep.shape)[keep], np.broadcast_to(d, keep.shape)[keep]
    at = np.argsort((-ds - sep) / ks, kind="stable")
    s = even(sep)
    for k, d in zip(ks[at].tolist(), ds[at].tolist(), strict=True):
        if k * s <= -d - sep:
            break               # (this interval, and every later one, starts above s)
        if k * s < sep - d:
            s = even(-((d - sep) // k))         # the interval's end, rounded up
            if s > limit:
                return None
    return s


def facts_cycles(t_rst_s=None, t_settle_s=None):
    """RST_ACTIVE and the settle time in ``dmd`` cycles: the facts table's (or the times given),
    without the sequencer's margins."""
    return tuple(math.ceil((TIMING[name].value if given is None else given) * FABRIC_HZ - 1e-9)
                 for name, given in (("t_rst_active", t_rst_s), ("t_settle", t_settle_s)))


def ceiling_of_mode(dmd, dclk_hz, reset_mode, *, depth=8, strict_rst=True, t_rst_s=None, t_settle_s=None,
                    beat=None):
    """The :class:`Ceiling` of one reset mode (None if none beats ``beat`` frame cycles);
    ``t_rst_s``, ``t_settle_s``: other timing than the facts table's."""
    R = row_cycles(dmd, beats_at(dclk_hz))
    t_rst, t_settle = facts_cycles(t_rst_s, t_settle_s)
    grp = groups(dmd, reset_mode)
    G, size = len(grp), max(len(b) for b in grp)
    reload = t_rst + t_settle + size * dmd.rows_per_block * R
    sep = t_rst if strict_rst else R
    lsb = even(t_rst + t_settle + size * dmd.clear_row_cycles * R)
    best = None
    orders = list(itertools.permutations(range(depth))) if G > 1 else [tuple(range(depth - 1, -1, -1))]
    while True:
        limit = beat if best is None else best.frame_cycles
        if limit is not None and (2 ** depth - 1) * lsb + reload + (G - 1) * sep >= limit:
            return best
        for order in orders:
            pulses, _ = timeline(order, lsb, reload, reload)
            room = None if limit is None else (limit - int(pulses[-1]) - reload) // max(G - 1, 1)
            if G > 1:
                if room is not None and room < sep:
                    continue
                s = _stagger(pulses, G, sep, room if room is not None else 1 << 40)
                if s is None:
                    continue
            else:
                s = 0
            frame = (G - 1) * s + int(pulses[-1]) + reload
            if limit is None or frame < limit:
                best = Ceiling(ResetMode(reset_mode), frame, order, lsb, s)
                limit = frame
        lsb += 2


def ceiling(dmd, dclk_hz, *, depth=8, strict_rst=True, workers=None, **timing):
    """The fastest one-timeline plan over every reset mode (a :class:`Ceiling`), and each mode's
    (a dict by mode; None where a mode cannot beat the global plan). The phased modes are
    searched in ``workers`` processes (default: one per core). ``timing``: ``t_rst_s``,
    ``t_settle_s`` as :func:`ceiling_of_mode` takes them."""
    plain = ceiling_of_mode(dmd, dclk_hz, ResetMode.GLOBAL, depth=depth, strict_rst=strict_rst, **timing)
    phased = [m for m in ResetMode if m != ResetMode.GLOBAL]
    args = [(dmd, dclk_hz, m) for m in phased]
    kwargs = {"depth": depth, "strict_rst": strict_rst, "beat": plain.frame_cycles, **timing}
    workers = min(len(args), workers or os.cpu_count() or 1)
    if workers > 1:
        with ProcessPoolExecutor(workers) as pool:
            found = list(pool.map(_mode, args, [kwargs] * len(args)))
    else:
        found = [_mode(a, kwargs) for a in args]
    each = {ResetMode.GLOBAL: plain, **dict(zip(phased, found, strict=True))}
    return min((c for c in each.values() if c is not None), key=lambda c: c.frame_cycles), each


def _mode(args, kwargs):
    return ceiling_of_mode(*args, **kwargs)
