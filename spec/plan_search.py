"""The plan finder: the fastest legal schedule for a DMD, a DCLK, a bit depth and a memory row
period, and the constraint that binds it.

:func:`spec.schedule.plan` makes one plan for a reset mode and a plane order; it chooses the
group stagger itself (pulses on the LSB lattice, or groups spread apart, whichever is faster) and
the smallest legal hide threshold (a plane at least ``hide`` long has the next plane loaded behind
it: the settle path and a load must fit in it). :func:`find` tries every reset mode and plane
order, and each higher hide threshold (a plane length: more planes then end in a dark pulse
instead), keeps what the schedule model plays with no pulse late (:func:`spec.schedule.on_time`),
and returns the fastest. The orders are most significant plane first, least significant first,
and :func:`interleaved` (each short plane behind a long one, so that the loads a short plane
must hide, the tight ones, fall far apart in the frame: phased groups then stagger less). Under
TI's rules a higher threshold is never faster, and neither is least significant plane first;
they are tried so that the table says so rather than assuming it.
The loose RST_ACTIVE reading is tried only when asked (``strict_rst=False``): TI's rule is the
default. ``python -m host configure --best`` uses it before sending, and prints the table.
"""

import os
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, replace

from .registers import PlaneOrder, ResetMode
from .schedule import Frame, Plan, exponents, frame_period, on_time, plan

__all__ = ["Candidate", "Found", "candidate", "find", "interleaved", "order_kwargs", "order_name", "ORDERS",
           "ORDER_NAMES"]

#: The plane orders tried, by name (``INTERLEAVED``: ``TABLE`` with :func:`interleaved`).
ORDER_NAMES = {"MSB_FIRST": PlaneOrder.MSB_FIRST, "LSB_FIRST": PlaneOrder.LSB_FIRST,
               "INTERLEAVED": PlaneOrder.TABLE}
ORDERS = tuple(ORDER_NAMES.values())


def order_name(order):
    """The name of one of :data:`ORDERS`."""
    return next((name for name, o in ORDER_NAMES.items() if o == order), PlaneOrder(order).name)


def interleaved(depth):
    """Weight exponents in display order: the longest plane, the second shortest, the next
    longest, the third shortest, ..., the shortest last (before the frame's final dark pulse);
    for 8 bits 7 1 6 2 5 3 4 0."""
    out, hi, lo = [], depth - 1, 1
    while hi >= lo:
        out.append(hi)
        hi -= 1
        if lo <= hi:
            out.append(lo)
            lo += 1
    return tuple(out + [0])


def order_kwargs(order, depth):
    """:func:`spec.schedule.plan`'s arguments for one of :data:`ORDERS`."""
    if order == PlaneOrder.TABLE:
        table = interleaved(depth)
        return {"order": order, "order_table": table + tuple(range(depth, 8))}
    return {"order": order}


@dataclass
class Candidate:
    """One plan tried: its reset mode, plane order and hide threshold; ``plan`` when it is legal
    (its rate and binding constraint), else ``why`` not."""
    reset_mode: ResetMode
    order: PlaneOrder
    hide: int
    plan: Plan | None = None
    why: str = ""

    @property
    def rate_hz(self):
        return self.plan.rate_hz if self.plan else 0.0

    @property
    def order_name(self):
        return order_name(self.order)

    def describe(self):
        head = f"{self.reset_mode.name:6} {self.order_name:11} hide {self.hide:>7}"
        if self.plan is None:
            return f"{head}  not legal: {self.why}"
        p = self.plan
        return f"{head}  {p.rate_hz:7.1f} Hz  {p.frame_cycles:>8} cycles  LSB {p.params.lsb:>6}  {p.binds}"


@dataclass
class Found:
    """The fastest legal candidate (``best``), every candidate in the order tried, and what binds
    the best one: its plan's constraint, and the choices that beat the others."""
    best: Candidate
    candidates: list

    @property
    def plan(self):
        return self.best.plan

    @property
    def binds(self):
        b = self.best
        return f"{b.reset_mode.name}, {b.order_name}, hide {b.hide}: {b.plan.binds}"

    def table(self):
        return "\n".join(("* " if c is self.best else "  ") + c.describe() for c in self.candidates)


def _higher_hides(base, depth):
    """Hide thresholds above ``base``'s that hide fewer planes' successors: each hidden plane's
    length but the shortest's (that plane and the longer ones go on hiding a load), and one above
    the longest (no plane hides a load)."""
    p = base.params
    lengths = sorted({p.lsb << e for e in exponents(p.order, p.order_table, depth)})
    hidden = [length for length in lengths if length >= p.hide]
    return hidden[1:] + [lengths[-1] + 2] if hidden else []


def _candidates(dmd, dclk_hz, depth, mode, order, hides, plan_kwargs):
    """The candidates of one reset mode and plane order: the plan, then each higher hide."""
    try:
        base = plan(dmd, dclk_hz, depth=depth, reset_mode=mode, **order_kwargs(order, depth), **plan_kwargs)
    except ValueError as error:
        return [Candidate(ResetMode(mode), order, 0, why=str(error))]
    out, frame = [Candidate(ResetMode(mode), order, base.params.hide, base)], Frame(0, depth)
    for hide in _higher_hides(base, depth) if hides else ():
        p = replace(base.params, hide=hide)
        if not on_time(dmd, p, frame):
            out.append(Candidate(ResetMode(mode), order, hide, why="a pulse late"))
            continue
        higher = replace(base, params=p, frame_cycles=frame_period(dmd, p, frame),
                         binds=base.binds + " (hide raised: more planes end dark)")
        out.append(Candidate(ResetMode(mode), order, hide, higher))
    return out


def candidate(dmd, dclk_hz, mode, order, hide, *, depth=8, **plan_kwargs):
    """The candidate :func:`find` makes of one reset mode, plane order and hide threshold (a
    choice found before, planned again without the search)."""
    for c in _candidates(dmd, dclk_hz, depth, mode, order, True, plan_kwargs):
        if c.hide == hide:
            return c
    raise ValueError(f"no candidate with hide {hide} for {ResetMode(mode).name}, {order_name(order)}")


def find(dmd, dclk_hz, *, depth=8, modes=tuple(ResetMode), orders=ORDERS, hides=True, workers=None,
         **plan_kwargs):
    """The fastest legal plan for ``dmd`` at ``dclk_hz`` and ``depth`` bits. ``modes``,
    ``orders``: what to try; ``hides``: try the higher hide thresholds too; ``plan_kwargs``: the
    rest of :func:`spec.schedule.plan`'s arguments (the memory's ``words_per_cycle``,
    ``strict_rst``, exposure, timing, trigger hold). The reset modes and orders are planned in
    ``workers`` processes (default: one per core; a phased plan takes seconds). Raises
    :class:`ValueError` when no candidate is legal."""
    jobs = [(dmd, dclk_hz, depth, mode, order, hides, plan_kwargs) for mode in modes for order in orders]
    workers = min(len(jobs), workers or os.cpu_count() or 1)
    if workers > 1:
        with ProcessPoolExecutor(workers) as pool:
            found = list(pool.map(_candidates, *zip(*jobs, strict=True)))
    else:
        found = [_candidates(*job) for job in jobs]
    candidates = [c for group in found for c in group]
    legal = [c for c in candidates if c.plan is not None]
    if not legal:
        raise ValueError(f"no legal plan for {dmd.name} at {dclk_hz / 1e6:g} MHz, {depth} bits")
    best = min(legal, key=lambda c: (c.plan.frame_cycles, candidates.index(c)))
    return Found(best, candidates)
