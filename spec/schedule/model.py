"""The schedule model: every DLPC410 command of a PWM frame, its cycle, the light per grey level.

It runs the very algorithm of :class:`gateware.dlpc410.sequencer.Sequencer`, event by event
instead of cycle by cycle (:func:`simulate`); :mod:`.measures` measures plans with it
(:func:`~.measures.frame_period`, :func:`~.measures.on_time`, :func:`~.measures.back_to_back`).

The algorithm
-------------
Blocks are pulsed in *groups* (:func:`spec.registers.group_size`): one group of all
blocks in global mode, groups of 4, 2 or 1 in the phased modes. Every group plays the same
timeline; group ``g`` runs ``g * stagger`` cycles behind group 0.

A frame of bit depth ``d`` is shown as ``d`` planes in the configured order; the plane of weight
``2**e`` is shown for ``lsb << e`` cycles, measured from its clocking pulse to the next pulse of
the same group; a gated plane (bit ``e`` of ``gated_planes``) for ``gated_time`` cycles, its light
on for ``light_times[e]`` of them (the gate pin; :mod:`gateware.dlpc410.light_gate`). After
each pulse the group's memory is frozen for ``t_rst + t_settle`` cycles; then the group is
loaded with what its next pulse shows:

* a plane at least ``hide`` long has the next plane loaded behind it, and the next pulse comes
  exactly ``lsb << e`` after this one;
* a shorter plane (and the last plane of a frame unless frames are chained) has its group's
  blocks cleared behind it and is ended by a *dark pulse* exactly on time; the next plane is
  loaded after that pulse's settle time and pulsed ``dark_gap`` after the dark pulse.

Loading a group: for each block, its rows (one row cycle each, ``row_period`` apart) when the
occupancy map says the plane has a bit set in the block, else one block clear
(``clear_row_cycles`` row cycles). Loads are served in the order they were queued (the order of
the pulses that freed them); a dark pulse's clears are queued apart and go first, once the
group's memory may change: they need no data from the store, and they have the shortest
deadline there is (the least significant plane's time less the settle path).

The command bus makes one decision every even cycle on which no row cycle is running (the
DLPC410 runs at DCLK/2, so gaps are even): a pulse whose time has come and whose group is
loaded, if the RST_ACTIVE rule allows it (strict: ``t_rst`` after any pulse; otherwise after the
same group's); else the oldest dark pulse's next clear if its group's settle time is over, or
else the next load operation, if its group's settle time is over, the row pacing allows it and
the oldest dark pulse's group's memory does not free before it ends (its clears would wait);
each only if no loaded pulse falls due before the operation ends; else nothing. A pulse that
cannot be made on time is made late and counted (the plan below never lets that happen).

A trigger strobe at cycle ``s`` is obeyed when every group is loaded and waiting: group ``g``'s
first pulse falls due at ``s + 2 + g * stagger`` (the frame control's decision takes a cycle);
otherwise it is counted as an overrun. In GROUPS, where each group's first pulse comes at its own
offset, once frames follow triggers, and group 0's offset is not 0, only group 0 must be loaded,
and RST_ACTIVE must allow its pulse: the others wait with their first loads under way, each due
by its own offset (the plan finder's plans make none late; a late one is counted), and group 0's
offset gives the bus time to end the operation under way when the trigger comes (a row, or a
block's clear: no pulse waits for it, whenever the trigger comes). With group 0's offset 0, and
after a start or a frame taken while waiting (every first plane queued at once), the trigger
waits for every group. A pulse due at ``T`` is made on the first free even cycle from
``even(T)`` on, and counts as late when made after ``even(T)``.

Frames: the first group to move on from a frame takes the next offered frame when it makes its
last pulse of the frame (else the frame repeats); the others take the same frame when they move
on. In one timeline that group is group 0; in GROUPS it is whichever group ends its frame first
(a group taking another frame than the one group 0 shows next would tear the frame).
Triggered and not chained, a frame offered while no group plays (every group has made its
frame's last pulse) is taken at once: every group's first plane is loaded again
from it, no sooner than ``reload_lead`` cycles later (the store's first words), unless the
triggers come at a steady pace and the next one is due before such a reload could end
(:func:`reload_bound`): then the newer frame waits for the trigger after, and no trigger is
delayed by it. A trigger before the load ends is held (``trigger_hold``) or an overrun. If the
first planes of the frame before were still being loaded (a frame
completed late, just after the last pulse), those loads are abandoned: the row cycle on the bus
ends, the queued loads are dropped, the words already asked of the store are discarded, and
the new loads start no sooner than ``reload_lead + flush_rows * row_period`` cycles later (nor
before each group's settle time ends, as always). Nothing abandoned is ever pulsed.

Time base: cycle 0 is the first cycle after initialisation (INIT_ACTIVE low); the first loads
may start at ``init_to_dvalid`` (64 clocks, DLPC910). Command cycles are decision cycles; the
pins show each command :data:`DECISION_TO_PINS` cycles later. A frame taken at ``t`` is answered
to the store on the next cycle, so the frame after it is offered no sooner than ``t + 2``; the
sequencer sees an offer :data:`OFFER_LAG` cycles after the store makes it.
"""

import math

from ..registers import (
    PlaneOrder,
    Source,
    TriggerMode,
)
from .terms import (
    CLEAR_HOLD_AFTER_RST,
    END_TO_TRIGGER,
    INIT_TO_DVALID,
    OFFER_LAG,
    PACE_LAG,
    Frame,
    Result,
    even,
    exponents,
    flush_rows,
    groups,
    reload_bound,
    row_cycles,
)

__all__ = ["simulate", "shows_depth"]


class _Group:
    def __init__(self):
        self.pending = False
        self.pulse_at = 0
        self.loaded_at = None     # cycle from which the group counts as loaded
        self.ended_at = -math.inf  # cycle of the dark pulse that ended its play
        self.writable = INIT_TO_DVALID
        self.rst_free = 0
        self.pos = None           # ("plane", frame_index, j) or ("dark", frame_index, j)


def shows_depth(p, depth, n_groups):
    """Whether the plane order of ``p`` shows a frame of ``depth`` planes on ``n_groups`` groups:
    1..8, and with an order table the first ``depth`` entries of every table in force (in
    GROUPS, each group's, as :meth:`Params.registers` writes it) name exponents 0..depth-1 (a
    frame the sequencer cannot show is dropped when offered, and counted)."""
    if not 1 <= depth <= 8:
        return False
    tables = {PlaneOrder.TABLE: [p.order_table],
              PlaneOrder.GROUPS: [list(t) + list(range(len(t), 8)) for t in p.group_tables[:n_groups]]}
    return all(sorted(t[:depth]) == list(range(depth)) for t in tables.get(p.order, []))


class _Frames:
    """The frames offered, in turn from their ``ready`` cycle (the store's answers), and the
    frames taken (``shown``). A frame with a bit depth the order does not show
    (:func:`shows_depth`) is dropped the cycle after it is offered."""

    def __init__(self, frames, result, p, n_groups):
        self.p, self.n_groups = p, n_groups
        self.offered = list(frames)
        self.shown = result.shown
        self.result = result
        self.offer_from = 0

    def offer(self):
        """(bad frames before it, cycle the sequencer sees it from) of the next good frame, or
        None. The store offers it from its ``ready`` cycle (a bad one before it is dropped the
        cycle after it is offered, the next offered the cycle after that); the sequencer sees an
        offer :data:`OFFER_LAG` cycles later. The time base stands at 0 until the controller is
        initialised, so what is offered at 0 is offered long before it runs: seen from 0, and a
        bad frame then dropped in no time."""
        at = self.offer_from
        for k, f in enumerate(self.offered):
            at = max(at, f.ready)
            if shows_depth(self.p, f.depth, self.n_groups):
                return k, at + OFFER_LAG if at > 0 else 0
            at += 2 if at > 0 else 0
        return None

    def take(self, t, repeat=True):
        """Take the frame offered at ``t``, if any: its index in ``shown``; else the last one
        taken (``repeat``) or None."""
        nxt = self.offer()
        if nxt is not None and nxt[1] <= t:
            del self.offered[:nxt[0]]
            self.result.bad_frames += nxt[0]
            self.shown.append(self.offered.pop(0))
            self.offer_from = t + 2
        elif not repeat:
            return None
        assert self.shown, "no frame offered before it was needed"
        return len(self.shown) - 1


class _Model:
    """The sequencer's algorithm, its parts as in the gateware: the planner (:meth:`enqueue`,
    :meth:`after_pulse`), the frame control (:meth:`take_while_waiting`, :meth:`strobe`) and the
    bus (:meth:`decide`), run event by event (:meth:`run`)."""

    def __init__(self, dmd, p, frames, strobes):
        self.dmd, self.p = dmd, p
        self.R = row_cycles(dmd, p.beats)
        self.row_period = p.row_period or self.R
        self.group_blocks = groups(dmd, p.reset_mode)
        self.G = len(self.group_blocks)
        self.states = [_Group() for _ in range(self.G)]
        self.result = Result([], [])
        self.result.groups = self.states
        self.queue = []                     # loads: [group, ops, index]
        self.darks = []                     # dark clears, apart: [group, ops, index]
        self.frames = _Frames([Frame(0, 1)] if p.source == Source.PRNG else frames, self.result, p, self.G)
        self.strobes = sorted(strobes)
        self.strobes_taken = 0              # strobes handled
        self.next_row = 0
        self.rst_any = 0
        self.next_frame = None
        # groups still showing the frame before ``next_frame``: the first group to move on to a
        # new frame takes the one offered (in one timeline, group 0; in GROUPS, whichever ends
        # its frame first), the others follow it
        self.behind = set()
        self.queued_at = self.G + 2         # the first planes are queued one group a cycle
        self.bus_free = 0
        self.t = 0
        self.holding = False                # a trigger held until every group is ready
        self.ended = False                  # a sequence played once has started its last frame
        self.reloaded = True                # every first plane queued at once since the last trigger
        self.idle_take = not p.chain and p.source != Source.PRNG
        # the trigger's pace (the guard of take_while_waiting): the periodic timer's is known
        # from the start (its first strobe comes ``period - 1`` cycles in), a pin's after two;
        # each strobe's pace counts from PACE_LAG cycles after it: (from, last strobe, interval)
        periodic = p.trigger == TriggerMode.PERIODIC
        self.last_strobe, self.interval = (-1, p.period) if periodic else (None, 0)
        self.paces = [(-math.inf, self.last_strobe, self.interval)]
        self.reload_bound = reload_bound(dmd, p)

    # -- the planner -------------------------------------------------------------------------

    def exps_of(self, fi, g):
        p = self.p
        table = p.group_tables[g] if p.order == PlaneOrder.GROUPS else p.order_table
        return exponents(p.order, table, self.result.shown[fi].depth, p.anchor)

    def enqueue(self, g, fi, j):
        """Queue the load of frame ``fi``'s display position ``j`` (None: clears) for group g."""
        dmd, frame = self.dmd, self.result.shown[fi]
        self.states[g].loaded_at = None
        if j is None:
            # a dark pulse's clears: queued apart, served before any load once the group's
            # memory may change (they need no data, and their window is the shortest plane's)
            self.darks.append([g, [("clear", b) for b in self.group_blocks[g]], 0])
            return
        ops = []
        plane = frame.stored_plane(self.exps_of(fi, g)[j])
        for b in self.group_blocks[g]:
            if self.p.source == Source.PRNG or frame.occupied(plane, b):
                ops += [("row", r) for r in range(b * dmd.rows_per_block, (b + 1) * dmd.rows_per_block)]
            else:
                ops.append(("clear", b))
        self.queue.append([g, ops, 0])

    def next_frame_for(self, g):
        """The frame group ``g`` moves on to: the one offered (or its own again) if it is the
        first group to move on, else the one the first took."""
        if g in self.behind:
            self.behind.discard(g)
        else:
            self.next_frame = self.frames.take(self.t)
            self.behind = set(range(self.G)) - {g}
        return self.next_frame

    def follows(self, g, t):
        """Whether the frame after group ``g``'s frame starts without a trigger: chained, or that
        frame follows (the first group to move on: the one offered now, if any, else its own
        again; the others: the one the first took); never after the last frame of a sequence
        played once."""
        p, frame = self.p, self.result.shown[self.states[g].pos[1]]
        if frame.last:
            return False
        after = self.result.shown[self.next_frame]
        nxt = self.frames.offer() if g not in self.behind and p.source != Source.PRNG else None
        if nxt is not None and nxt[1] <= t:
            after = self.frames.offered[nxt[0]]
        return p.chain or after.follow

    def after_pulse(self, g, t):
        p, s = self.p, self.states[g]
        kind, fi, j = s.pos
        frame = self.result.shown[fi]
        exps = self.exps_of(fi, g)
        last = j == len(exps) - 1
        follow = last and self.follows(g, t)
        if kind == "plane":
            d = p.plane_time(exps[j], frame.lsb)
            s.pulse_at = t + d
            if d >= p.hide and (not last or (follow and not frame.dark)):
                nfi, nj = (fi, j + 1) if not last else (self.next_frame_for(g), 0)
                s.pos = ("plane", nfi, nj)
                self.enqueue(g, nfi, nj)
            else:
                s.pos = ("dark", fi, j)
                self.enqueue(g, fi, None)
        else:
            s.pulse_at = t + (max(p.dark_gap, frame.dark) if last else p.dark_gap)
            nfi, nj = (fi, j + 1) if not last else (self.next_frame_for(g), 0)
            s.pos = ("plane", nfi, nj)
            if last and not follow:
                s.pending = False
                s.ended_at = t
            self.enqueue(g, nfi, nj)

    def waiting(self, t):
        """Every group waits, loaded."""
        return all(not s.pending and s.loaded_at is not None and s.loaded_at <= t for s in self.states)

    def steady(self):
        """In GROUPS with group 0 offset (its offset room for the bus to end an operation under
        way when the trigger comes), frames follow a trigger's: each group's first plane was
        queued at its own last dark pulse (not all at once, by a start or a frame taken while
        waiting)."""
        p = self.p
        return p.order == PlaneOrder.GROUPS and p.group_offsets[0] != 0 and not self.reloaded

    def needs_loaded(self):
        """The groups that must be loaded for a trigger to be obeyed: every one, or when
        :meth:`steady` group 0 only (each other group's first pulse comes at its own offset, its
        load under way)."""
        return self.states[:1] if self.steady() else self.states

    def trigger_ready(self, t):
        """A trigger may be obeyed at ``t``: no group plays (each ended its play
        :data:`END_TO_TRIGGER` cycles ago at least), and :meth:`needs_loaded` are loaded."""
        return (not self.playing() and all(s.ended_at + END_TO_TRIGGER <= t for s in self.states)
                and all(s.loaded_at is not None and s.loaded_at <= t for s in self.needs_loaded())
                and self.first_rst_free() <= t)

    def first_rst_free(self):
        """When :meth:`steady`, the first cycle a trigger may be obeyed at as far as RST_ACTIVE
        goes: group 0's first pulse, its offset on, need not wait for it; else no bound (every
        group loaded: its last pulse is long past)."""
        if not self.steady():
            return -math.inf
        return self.rst_any if self.p.strict_rst else self.states[0].rst_free

    def playing(self):
        return any(s.pending for s in self.states)

    # -- the frame control -------------------------------------------------------------------

    def start(self):
        self.reloaded = True
        fi = self.next_frame = self.frames.take(self.t)
        self.behind = set()
        for g in range(self.G):
            self.states[g].pos = ("plane", fi, 0)
            self.enqueue(g, fi, 0)

    def takes_idle(self, k):
        """Offered frame ``k`` replaces the waiting one: a streamed frame, or any once a sequence
        played once has ended (a sequence frame otherwise waits for its turn)."""
        return not self.frames.offered[k].sequence or self.ended

    def pace(self, t):
        """(last strobe, interval) as the frame control knows them at ``t``."""
        return [(last, interval) for since, last, interval in self.paces if since <= t][-1]

    def fits(self, t):
        """A newer frame may replace the waiting one at ``t`` unless the triggers come at a steady
        pace (the periodic timer's, or the last two ``interval`` apart) and the next one is due
        before a reload could end (:func:`reload_bound`): that trigger is not delayed, the newer
        frame is shown at the one after. Once the next trigger is an eighth of an interval
        overdue, the pace counts as broken."""
        last, interval = self.pace(t)
        if not interval:
            return True
        due = last + interval
        return t > due + (interval >> 3) or t + self.reload_bound < due

    def fits_from(self, t):
        """The first cycle from ``t`` on at which :meth:`fits` holds (within one pace it only
        grows more likely once the next trigger is overdue)."""
        switches = sorted(since for since, _last, _interval in self.paces if since > t)
        for start, end in zip([t, *switches], [*switches, None], strict=True):
            if self.fits(start):
                return start
            last, interval = self.pace(start)
            overdue = last + interval + (interval >> 3) + 1
            if end is None or overdue < end:
                return overdue
        raise AssertionError("unreachable")

    def take_while_waiting(self, t):
        """A newer frame offered while no group plays: load its first plane, abandoning the
        stale loads still queued (their words are discarded for ``flush_rows`` row periods)."""
        wait = 0 if self.waiting(t) else flush_rows(self.dmd) * self.row_period
        fi = self.next_frame = self.frames.take(t, repeat=False)
        self.behind = set()
        self.ended = False
        self.reloaded = True
        self.queued_at = t + max(wait, 1) + self.G + 1
        self.queue.clear()
        self.darks.clear()
        for g in range(self.G):
            self.states[g].pos = ("plane", fi, 0)
            self.states[g].writable = max(self.states[g].writable, t + self.p.reload_lead + wait)
            self.enqueue(g, fi, 0)

    def obey(self, t):
        """Every group's first pulse due from ``t + 2``, staggered."""
        self.result.accepted.append(t)
        self.reloaded = False
        for g, s in enumerate(self.states):
            s.pending = True
            s.pulse_at = t + 2 + (self.p.group_offsets[g] if self.p.order == PlaneOrder.GROUPS else g * self.p.stagger)

    def release_held(self, t):
        """A held trigger is obeyed on the first cycle every group is ready."""
        if self.holding and self.trigger_ready(t):
            self.holding = False
            self.obey(t)

    def strobe(self, s_t):
        """A trigger strobe at ``s_t`` (reads the state before this cycle's decision): obeyed,
        held (``trigger_hold``, one at a time) or an overrun."""
        if self.last_strobe is not None and self.p.trigger != TriggerMode.PERIODIC:
            self.interval = s_t - self.last_strobe
        self.last_strobe = s_t
        self.paces.append((s_t + PACE_LAG, self.last_strobe, self.interval))
        if self.ended:
            self.result.ended += 1
        elif self.trigger_ready(s_t):
            self.obey(s_t)
        elif self.p.trigger_hold and not self.holding:
            self.holding = True
            self.result.held += 1
        else:
            self.result.overruns += 1

    def ready_at(self):
        """The cycle a trigger may be obeyed from (:meth:`trigger_ready`) as things stand, or None."""
        need = self.needs_loaded()
        if self.playing() or any(s.loaded_at is None for s in need):
            return None
        return max([s.loaded_at for s in need] + [s.ended_at + END_TO_TRIGGER for s in self.states]
                   + [self.first_rst_free()])

    # -- the bus -----------------------------------------------------------------------------

    def decide(self, t):
        """The bus's decision at an even free cycle: a due pulse, else the next clear of the
        oldest dark pulse's group once its memory may change, else the next load operation
        (unless it would hold up those clears: :meth:`clears_soon`), else nothing. Returns True
        when a pulse was made."""
        p, states, result, R = self.p, self.states, self.result, self.R
        rst_ok = [t - (self.rst_any if p.strict_rst else states[g].rst_free) >= 0 for g in range(self.G)]
        due = [g for g in range(self.G) if states[g].pending and states[g].loaded_at is not None
               and states[g].loaded_at <= t and states[g].pulse_at <= t and rst_ok[g]]
        if due:
            g = due[0]
            s = states[g]
            if even(s.pulse_at) < t:
                result.late += 1
            kind, fi, j = s.pos
            result.commands.append((t, "pulse", tuple(self.group_blocks[g])))
            result.pulses.append((t, g, kind, fi, self.exps_of(fi, g)[j] if kind == "plane" else None))
            if kind == "plane" and j == 0 and g == 0:
                result.frame_starts.append(t)
                frame = result.shown[fi]
                if not frame.camera_off:
                    result.camera_starts.append(t)
                self.ended = self.ended or frame.last
            s.rst_free = t + p.t_rst
            self.rst_any = t + p.t_rst
            s.writable = t + p.t_rst + p.t_settle
            self.bus_free = t + R
            self.after_pulse(g, t)
            return True
        queue = self.darks if self.darks and t >= states[self.darks[0][0]].writable else self.queue
        if queue:
            g, ops, i = queue[0]
            op, arg = ops[i]
            length = R if op == "row" else self.dmd.clear_row_cycles * R
            imminent = any(states[h].pending and states[h].loaded_at is not None and states[h].loaded_at <= t
                           and even(states[h].pulse_at) < t + length for h in range(self.G))
            held = queue is self.queue and self.clears_soon(t, length)
            result.loads_held += held and t >= states[g].writable and not imminent
            if t >= states[g].writable and not imminent and not held and (op != "row" or t >= self.next_row):
                result.commands.append((t, op, arg))
                for k in range(1, self.dmd.clear_row_cycles if op == "clear" else 1):
                    result.commands.append((t + k * R, "noop", None))
                if op == "row":
                    self.next_row = t + self.row_period
                self.bus_free = t + length
                queue[0][2] += 1
                if queue[0][2] == len(ops):
                    queue.pop(0)
                    states[g].loaded_at = t + length
        return False

    def clears_soon(self, t, length):
        """A load operation of ``length`` cycles decided at ``t`` would hold up the oldest dark
        pulse's clears: that group's RST_ACTIVE count is over and its memory frees before the
        operation ends (the clears' deadline is the shortest plane's, a load's is a long one's)."""
        if not self.darks:
            return False
        s = self.states[self.darks[0][0]]
        return t >= s.rst_free + CLEAR_HOLD_AFTER_RST and s.writable <= t + length - 2

    # -- time --------------------------------------------------------------------------------

    def next_time(self):
        """The next cycle at which anything can happen, and the cycle a waiting frame is taken
        (None if none)."""
        t, p, states = self.t, self.p, self.states
        cands = []
        if self.strobes_taken < len(self.strobes):
            cands.append(self.strobes[self.strobes_taken])
        for s in states:
            if s.pending and s.loaded_at is not None:
                cands.append(max(s.pulse_at, s.rst_free if not p.strict_rst else self.rst_any))
        if self.darks:
            cands.append(states[self.darks[0][0]].writable)
        if self.queue:
            g, ops, i = self.queue[0]
            cands.append(max(states[g].writable, self.next_row) if ops[i][0] == "row" else states[g].writable)
        nxt = self.frames.offer()
        take_at = None
        if self.idle_take and nxt is not None and not self.playing() and self.takes_idle(nxt[0]):
            take_at = self.fits_from(max(nxt[1], self.queued_at, t + 1))
            cands.append(take_at)
        hold_at = None
        if self.holding and self.ready_at() is not None:
            hold_at = max(self.ready_at(), t + 1)
            cands.append(hold_at)
        if not cands:
            return None
        nt = max(t + 1, min(cands), self.bus_free)
        # (a strobe, a take or a held trigger's release is seen on its cycle, the bus busy or
        # not: the bus's next decision knows of the pulses it times)
        strobe_at = self.strobes[self.strobes_taken] if self.strobes_taken < len(self.strobes) else None
        for exact in (take_at, hold_at, strobe_at):
            if exact is not None and t < exact < nt:
                nt = exact
        strobe_next = self.strobes_taken < len(self.strobes) and self.strobes[self.strobes_taken] == nt
        if nt % 2 and not strobe_next and nt not in (take_at, hold_at):
            nt += 1
        return nt

    def run(self, until=None, max_frames=None):
        self.start()
        while True:
            t = self.t
            nxt = self.frames.offer()
            take_now = (self.idle_take and nxt is not None and nxt[1] <= t and t >= self.queued_at
                        and not self.playing() and self.takes_idle(nxt[0]) and self.fits(t))
            if t % 2 == 0 and t >= self.bus_free and self.decide(t):
                if max_frames is not None and len(self.result.frame_starts) > max_frames:
                    break
            if take_now:
                self.take_while_waiting(t)
            self.release_held(t)
            while self.strobes_taken < len(self.strobes) and self.strobes[self.strobes_taken] <= t:
                self.strobes_taken += 1
                self.strobe(self.strobes[self.strobes_taken - 1])
            nt = self.next_time()
            if nt is None or (until is not None and nt >= until):
                break
            self.t = nt
        return self.result


def simulate(dmd, p, frames, strobes=(), *, until=None, max_frames=None):
    """Run the sequencer's algorithm.

    Parameters
    ----------
    dmd : DmdType
    p : Params
    frames : list of Frame
        Offered in turn from their ``ready`` cycle (one frame per cycle at most; a frame with a
        bad bit depth is dropped the cycle it is offered): each time group 0 needs a new frame
        it takes the offered one, else shows the current one again; triggered and not chained,
        one offered while every group waits loaded for a trigger is taken at once (unless it is
        the next frame of a stored sequence). Each is shown as its fields say (a sequence
        entry's exposure, dark time, follow, camera and last).
    strobes : iterable of int
        Cycles at which the trigger block signals a trigger (see :mod:`gateware.dlpc410.trigger`).
    until : int
        Stop at this cycle (default: when nothing is left to do).
    max_frames : int
        Stop once this many frames have started (and one more pulse).
    """
    return _Model(dmd, p, frames, strobes).run(until=until, max_frames=max_frames)
