"""The planner: the fastest parameter set the sequencer plays on time for a DMD, a clock, a
depth and a reset mode (:func:`plan`), the search that spreads the groups' pulses apart, and the
bound no schedule passes (:func:`bound`, derived in ``docs/bounds.md``).
"""

import math
from dataclasses import dataclass, replace
from itertools import islice

import numpy as np

from ..facts import SETTLE_READINGS, TIMING
from ..registers import (
    PlaneOrder,
    ResetMode,
    Source,
    clear_cycles,
)
from .measures import (
    frame_period,
    on_time,
)
from .terms import (
    FABRIC_HZ,
    FALL_LATENCY,
    LIGHT_FALL,
    MIRRORS_SETTLED,
    PAPER_SETTLE_CYCLES,
    RELOAD_LEAD,
    RST_MARGIN,
    Frame,
    Params,
    beats_at,
    even,
    exponents,
    groups,
    row_cycles,
)

__all__ = [
    "Plan", "plan", "plan_gated", "bound", "paper_eq_rate_hz", "timeline",
]


# ---------------------------------------------------------------------------------------------
# Planning: from physical numbers to a consistent parameter set, and the bounds.

@dataclass
class Plan:
    """A checked parameter set: ``frame_cycles`` is the shortest trigger-to-trigger period
    (or the chained frame period), ``lsb_min`` the shortest legal least significant plane and
    ``binds`` the constraint that sets it."""
    params: Params
    frame_cycles: int             # trigger-to-trigger minimum (or chained frame period)
    lsb_min: int
    binds: str                    # which constraint sets the LSB
    dclk_hz: float

    @property
    def rate_hz(self):
        return FABRIC_HZ / self.frame_cycles

    @property
    def trigger_cycles(self):
        """The shortest period of triggers that may come on any cycle: ``frame_cycles`` is for
        triggers on the even cycles it is measured from (frames back to back); a trigger on an
        odd cycle is obeyed as one on the even cycle after it."""
        return self.frame_cycles + (0 if self.params.chain else 1)


def _cycles(seconds):
    return even(math.ceil(seconds * FABRIC_HZ - 1e-9))


def _lattice_ok(M, s, G, sep):
    """Pulses of distinct groups keep ``sep`` cycles apart when every timeline step is a
    multiple of ``M`` and group g is offset by ``g * s``."""
    for k in range(1, G):
        r = (k * s) % M
        if r < sep or M - r < sep:
            return False
    return True


def plan(dmd, dclk_hz, *, depth=8, order=PlaneOrder.MSB_FIRST, reset_mode=ResetMode.GLOBAL,
         exposure_s=0.0, strict_rst=True, chain=False, words_per_cycle=1.0, source=Source.STORE,
         t_rst_s=None, t_settle_s=None, frame=None, order_table=(7, 6, 5, 4, 3, 2, 1, 0),
         reload_lead=RELOAD_LEAD, trigger_hold=False, t_rst_cycles=None, reading="ti", anchor=0):
    """A parameter set that shows every plane exactly on time, and the rate it reaches.

    ``exposure_s`` asks for a least significant plane at least that long (0: the shortest legal
    one). ``words_per_cycle`` is the store's read bandwidth in 64-bit words per ``dmd`` cycle; it
    sets the row pacing. The plan is checked by simulating one frame (all blocks full unless
    ``frame`` is given): no pulse may be late.

    Phased modes: every step of a group's timeline is a multiple of the LSB duration, which is
    chosen (searching upward from the shortest legal one) so that the offsets ``g * stagger``
    never bring pulses of two groups closer than the RST rule allows (strict: ``t_rst``; loose:
    one row cycle) and the loads squeezed between other groups' pulses still finish on time.
    For triggered multi-bit frames the plan with groups spread apart (:func:`_spread`) is taken
    instead when it is faster; ``binds`` then names the load queue order.
    ``reload_lead``: the store's latency to a row's first words, in cycles (see :class:`Params`).
    ``trigger_hold``: a trigger that comes too early is held until every group is ready, rather
    than counted as an overrun.
    ``t_rst_cycles``: the controller's own RST_ACTIVE as the projector measured it (the status
    reply's ``rst_active_cycles_max``, from the pulse's decision to the fall at the pin), plus
    the synchroniser's :data:`FALL_LATENCY` (the strict reading's pin check sees the fall that
    much later), taken as ``t_rst`` instead of the facts table's time plus :data:`RST_MARGIN`.
    ``reading``: a key of :data:`spec.facts.SETTLE_READINGS`. TI's (default) freezes a pulsed
    group's memory for ``t_rst + t_settle``; the four-DMD paper's frees it once RST_ACTIVE falls
    (``t_settle`` register :data:`PAPER_SETTLE_CYCLES`) and keeps the group's pulses ``t_settle``
    apart instead (``t_flip``).
    """
    beats = beats_at(dclk_hz)
    R = row_cycles(dmd, beats)
    t_rst = even(t_rst_cycles + FALL_LATENCY) if t_rst_cycles is not None else \
        even(_cycles(TIMING["t_rst_active"].value if t_rst_s is None else t_rst_s) + RST_MARGIN)
    t_settle = _cycles(TIMING["t_settle"].value if t_settle_s is None else t_settle_s)
    t_flip = 0
    if SETTLE_READINGS[reading].flip:
        t_settle, t_flip = PAPER_SETTLE_CYCLES, t_settle
    words = dmd.words_per_row
    # the on-chip source needs no memory bandwidth: one row per row cycle on any bus width
    row_period = R if source == Source.PRNG else even(max(R, math.ceil(words / words_per_cycle - 1e-9)))
    grp = groups(dmd, reset_mode)
    G = len(grp)
    rows_g = max(len(b) for b in grp) * dmd.rows_per_block
    load_g = (rows_g - 1) * row_period + R
    clear_g = max(len(b) for b in grp) * clear_cycles(R, dmd.clear_row_cycles)
    stagger = 0 if G == 1 else even(max(load_g, t_rst if strict_rst else R))
    if depth == 1 and chain and G > 1:
        # patterns back to back keep the bus busy: each group's rows at the row period, and its
        # pulse's row cycle, before the next group's load can begin (a shorter stagger drifts:
        # each pattern's loads end later until pulses come late)
        stagger = even(max(stagger, rows_g * row_period + R))
    sep = t_rst if strict_rst else R
    settle_path = t_rst + t_settle + clear_g
    bus_path = stagger * G if G > 1 else 0
    lsb_min = max(settle_path, 2)
    binds = "settle (t_rst + t_settle + clears)"
    if depth == 1 and chain:
        lsb_min = max(t_rst + t_settle + load_g, bus_path, 2)
        binds = "bus (row loads)" if G > 1 and bus_path >= t_rst + t_settle + load_g \
            else "settle + load (a pulse freezes its group's memory)"
    if t_flip > lsb_min:
        lsb_min, binds = t_flip, "flip spacing (the paper's reading: t_settle between a block's pulses)"
    want = _cycles(exposure_s)
    if want > lsb_min:
        lsb_min, binds = want, "requested exposure"
    # slack for other groups' pulses stealing row cycles during a load
    slack = 0 if G == 1 else 4 * R
    hide = t_rst + t_settle + load_g + slack
    lsb = even(lsb_min)
    for _ in range(100000):
        if G == 1 or _lattice_ok(lsb, stagger, G, sep):
            # phased: on the LSB lattice that keeps groups' pulses apart; global: no lattice
            reload = t_rst + t_settle + load_g + slack
            dark_gap = even(max(reload, t_flip)) if G == 1 else lsb * math.ceil(reload / lsb)
            p = Params(lsb=lsb, t_rst=t_rst, t_settle=t_settle, hide=hide, dark_gap=dark_gap,
                       reset_mode=reset_mode, order=order, order_table=order_table, anchor=anchor,
                       chain=chain, strict_rst=strict_rst, source=source, stagger=stagger, row_period=row_period,
                       reload_lead=reload_lead, beats=beats, trigger_hold=trigger_hold, t_flip=t_flip)
            fr = frame or Frame(0, depth)
            if on_time(dmd, p, fr):
                break
        lsb += max(2, even(lsb // 128))
    else:
        raise ValueError("no feasible schedule found")
    floor = binds
    if lsb > lsb_min and binds != "requested exposure":
        binds += " + pulse spacing" if G > 1 else ""
    frame_cycles = frame_period(dmd, p, fr)
    if G > 1 and not chain and depth > 1:
        # phased PWM: the LSB lattice against spread groups, whichever is faster
        spread = _spread(dmd, replace(p, dark_gap=even(max(t_rst + t_settle + load_g + slack, t_flip))), fr,
                         even(lsb_min), sep, load_g, clear_g, frame_cycles)
        if spread is not None:
            p, frame_cycles = spread
            binds = (f"{floor} + load queue order: groups spread so that "
                     "no group's clears wait behind another group's plane load"
                     if p.lsb == even(lsb_min) else
                     "load queue order + pulse spacing (groups spread, LSB above the settle path)")
    return Plan(p, frame_cycles, lsb_min, binds, dclk_hz)


def plan_gated(dmd, dclk_hz, *, depth=8, chain=False, **options):
    """A gated plan: every plane of a ``depth``-bit frame gated (the gate pin switches the light),
    each the same shortest legal time ``T``, its light on ``light_times[0] << e`` of it. ``T`` is the binary
    plan's (:func:`plan`, global reset mode, ``options`` as its) reload, which every plane then
    hides behind it, or what the mirrors' settle, the largest plane's light and the source's
    fall need if longer; the least significant plane's light, ``light_times[0]``, is the most
    that lets the largest plane's light end by the next pulse (``lsb`` stays the binary plan's).
    ``frame_cycles`` is measured on the model as :func:`plan`'s; ``binds`` names what sets ``T``."""
    binary = plan(dmd, dclk_hz, depth=depth, reset_mode=ResetMode.GLOBAL, chain=chain, **options)
    p = binary.params
    reload = p.hide
    lead = even(MIRRORS_SETTLED)
    need = lead + (1 << (depth - 1)) * 2 + LIGHT_FALL
    gated_time = even(max(reload, need, p.t_rst + p.t_settle + clear_cycles(row_cycles(dmd, p.beats),
                                                                            dmd.clear_row_cycles) * dmd.blocks))
    binds = "reload (t_rst + t_settle + the rows)" if gated_time == even(reload) else "mirror settle + light"
    unit = (gated_time - lead - LIGHT_FALL) >> (depth - 1)
    mask = 0xFF
    q = replace(p, gated_planes=mask, gated_time=gated_time, light_lead=lead,
                light_times=tuple(unit << e for e in range(8)))
    fr = Frame(0, depth)
    if not on_time(dmd, q, fr):
        raise ValueError("the gated plan makes a pulse late")
    return Plan(q, frame_period(dmd, q, fr), gated_time, binds, dclk_hz)


def timeline(exps, lsb, hide, dark_gap):
    """One group's frame of planes of weight exponents ``exps`` (in display order): the time of
    each pulse from the first (the last: the frame's final dark pulse), and whether each one's
    plane ends in a dark pulse (a plane shorter than ``hide``, or the last; the next plane comes
    ``dark_gap`` after the dark pulse) rather than hiding the next plane's load."""
    pulses, darks, t = [], [], 0
    for j, e in enumerate(exps):
        pulses.append(t)
        t += lsb << e
        dark = (lsb << e) < hide or j == len(exps) - 1
        darks.append(dark)
        if dark:
            pulses.append(t)
            darks.append(False)
            t += dark_gap
    return np.array(pulses), darks


def _spread(dmd, p, fr, lsb_min, sep, load_g, clear_g, beat):
    """Phased PWM with groups spread apart instead of on the LSB lattice: every group plays the
    plain timeline (dark gaps not rounded to LSB multiples) ``stagger`` after the one before.
    Loads are served in the order of the pulses that freed them (a dark pulse's clears go
    first, once the group's memory may change): the stagger is the smallest
    that keeps every pulse ``sep`` from every other group's (RST_ACTIVE) and every load inside
    its deadline with the loads in queue order; each candidate is then checked by
    :func:`simulate`. Returns (params, frame cycles) if faster than ``beat`` cycles, else None."""
    G = len(groups(dmd, p.reset_mode))
    frozen = p.t_rst + p.t_settle
    margin = 2 * row_cycles(dmd, p.beats) * G   # other groups' pulses taking row cycles
    exps = exponents(p.order, p.order_table, fr.depth, p.anchor)
    best = None
    step = max(2, even(lsb_min // 64))
    for lsb in range(lsb_min, lsb_min + lsb_min // 4, step):
        pulses, darks = timeline(exps, lsb, p.hide, p.dark_gap)
        jobs = [clear_g if dark else load_g for dark in darks]
        cap = ((beat if best is None else best[1]) - int(pulses[-1])) // (G - 1)
        if cap <= sep:
            break
        diffs = np.unique(pulses[:, None] - pulses[None, :])      # sorted
        stag = np.arange(even(sep), min(cap, int(pulses[-1])), 2)
        ok = np.ones(len(stag), bool)
        for k in range(1, G):
            ok &= _distance_to_nearest(diffs, -k * stag) >= sep
        stag = stag[ok]
        for stagger in islice(_staggers_whose_loads_fit(dmd, p, pulses, darks, jobs, G, stag, frozen, clear_g,
                                                        margin), 4):
            q = replace(p, lsb=lsb, stagger=int(stagger))
            if on_time(dmd, q, fr):
                cycles = frame_period(dmd, q, fr)
                if cycles < (beat if best is None else best[1]):
                    best = (q, cycles)
                break
    return best


def _distance_to_nearest(values, points):
    """For each of ``points``, its distance to the nearest of ``values`` (sorted, not empty):
    the nearer of its two neighbours in order."""
    i = np.searchsorted(values, points)
    return np.minimum(np.abs(values[np.minimum(i, len(values) - 1)] - points),
                      np.abs(values[np.maximum(i - 1, 0)] - points))


def _staggers_whose_loads_fit(dmd, p, pulses, darks, jobs, G, stag, frozen, clear_g, margin):
    """The staggers of ``stag`` (increasing) at which every load of the groups spread that far
    apart, served in queue (pulse) order, ends inside its deadline (:func:`_spread`), smallest
    first: worked out 2,048 staggers at a time, as the search wants only the first few."""
    # the last pulse's load (the next frame's first plane) has no deadline but takes the bus
    offsets = np.repeat(np.arange(G), len(pulses))
    deadline = np.tile(np.append(pulses[1:], 1 << 62), G)
    for first in range(0, len(stag), 2048):
        part = stag[first:first + 2048]
        starts = np.tile(pulses, G)[None, :] + offsets[None, :] * part[:, None]
        order = np.argsort(starts, axis=1, kind="stable")
        starts = np.take_along_axis(starts, order, axis=1)
        deadlines = np.take_along_axis(deadline[None, :] + offsets[None, :] * part[:, None], order, axis=1)
        lengths = np.tile(np.array(jobs), G)[order]
        dark = np.tile(np.array(darks), G)[order]
        end = np.zeros(len(part), np.int64)
        fits = np.ones(len(part), bool)
        for i in range(starts.shape[1]):
            # a dark pulse's clears go before the loads once the memory may change (a row under
            # way, or another group's clear, first)
            done = np.maximum(end, starts[:, i] + frozen) + lengths[:, i]
            cleared = starts[:, i] + frozen + clear_g + 2 * row_cycles(dmd, p.beats)
            fits &= np.where(dark[:, i], cleared, done + margin) <= deadlines[:, i]
            end = np.where(dark[:, i], end, done)
        yield from part[fits]


def bound(dmd, dclk_hz, depth=8, *, t_rst_s=None, t_settle_s=None, reading="ti"):
    """Upper bound on the continuous-light PWM frame rate, any schedule: the least significant
    plane lasts at least RST_ACTIVE + settle + one clear row cycle (TI's reading; the paper's:
    RST_ACTIVE + a clear, and no less than the settle time), and a frame is ``2**depth - 1``
    such units (derivation: ``docs/bounds.md``)."""
    t_rst = TIMING["t_rst_active"].value if t_rst_s is None else t_rst_s
    t_settle = TIMING["t_settle"].value if t_settle_s is None else t_settle_s
    t_clear = dmd.clear_row_cycles * dmd.dclk_per_row / dclk_hz
    t0 = t_rst + t_settle + t_clear if SETTLE_READINGS[reading].frozen else max(t_rst + t_clear, t_settle)
    return 1 / ((2 ** depth - 1) * t0)


#: The four-DMD paper's 8-bit frame (eq. 6-7): 255 units of the settle time, then, not weighted,
#: its reset waits and the loads no plane hides.
PAPER_RESET_WAITS, PAPER_LOADS = 11, 3


def paper_eq_rate_hz(dmd, dclk_hz):
    """The four-DMD paper's own 8-bit rate (eq. 6-7) for ``dmd`` at ``dclk_hz``: a frame is 255
    settle times, :data:`PAPER_RESET_WAITS` RST_ACTIVE times and :data:`PAPER_LOADS` full loads
    (``rows * dclk_per_row`` DCLK cycles). Arithmetic, not a schedule: a ``_model`` figure."""
    load = dmd.rows * dmd.dclk_per_row / dclk_hz
    frame = (255 * TIMING["t_settle"].value + PAPER_RESET_WAITS * TIMING["t_rst_active"].value
             + PAPER_LOADS * load)
    return 1 / frame
