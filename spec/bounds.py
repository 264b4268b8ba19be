"""Frame-rate bounds past one DMD's PWM: more bits, a gated source, two DMDs in weighted light
(derivation: ``docs/bounds.md``, "Beyond one DMD").

Each bound is a closed form in ``dmd`` cycles (:data:`spec.schedule.FABRIC_HZ`) from TI's rules
as the facts table and the schedule's terms give them: ``t_rst`` and ``t_settle`` without the
sequencer's margins (:func:`spec.ceiling.facts_cycles`), a row cycle ``R``
(:func:`spec.schedule.row_cycles`), a block clear (``clear_row_cycles`` row cycles) and a plane's
load (every row, one every ``row_period`` cycles: ``R`` at the bus's pace, more at the memory's).
A frame shorter than the bound breaks one of those rules; what binds says which.

* ``one``: binary-weighted PWM on one DMD. Its least significant plane is at least the settle
  path ``t_rst + t_settle + clear`` (``2**n - 1`` of them a frame), and the bus loads ``n``
  planes a frame: the frame is the longer of the two.
* ``gated``: every plane shown for the same plane time ``T``, the light on for the plane's weight
  only. ``T`` is what a binary pattern needs in global reset (``t_rst + t_settle`` frozen, then the
  next plane's rows), unless the longest light pulse, its lead and the source's edge need more.
* ``dual``: two DMDs in lockstep, one showing the high ``n - k`` bits, one the low ``k`` at
  ``2**-k`` of the light, the same LSB: the frame of a ``max(k, n - k)``-bit frame on one DMD.
* ``dual_gated``: both boards gated: ``max(k, n - k) * T``.
"""

import math
from dataclasses import dataclass

from .ceiling import facts_cycles
from .facts import LIGHT, MEMORY, TIMING
from .schedule import FABRIC_HZ, beats_at, row_cycles

__all__ = ["Bound", "Paces", "one", "gated", "dual", "dual_gated", "plane_time", "gate_lead", "LEADS",
           "SCHEMES", "SHORTEST", "sequence_frames", "MEMORIES", "DEPTHS"]

#: The depths the bounds are stated at.
DEPTHS = tuple(range(1, 17))
#: What the source's lead after a pulse waits for, by name: ``settle`` the facts table's RST_ACTIVE
#: and settle time (TI's rule that the mirrors are settled), ``switch`` the pulse to the start of
#: the mirrors' motion and their switching time.
LEADS = {"settle": ("t_rst_active", "t_settle"), "switch": ("t_pulse_to_mirror", "t_switch")}
#: The memories a stored sequence lives in: the Atlys's DDR2, the SVEC's DDR3 on bank 4.
MEMORIES = {"atlys_ddr2": "bytes", "svec_ddr3": "svec_bank4_bytes"}


@dataclass(frozen=True)
class Paces:
    """The terms one DMD's bounds are counted in, ``dmd`` cycles: RST_ACTIVE, the settle time, a
    row cycle, a block clear, and a row of the store every ``row_period`` cycles."""
    t_rst: int
    t_settle: int
    row: int
    clear: int
    rows: int
    row_period: int

    @classmethod
    def of(cls, dmd, dclk_hz, row_period=None):
        """The terms of ``dmd`` at ``dclk_hz``; ``row_period`` None: the bus's pace (a row every
        row cycle)."""
        t_rst, t_settle = facts_cycles()
        R = row_cycles(dmd, beats_at(dclk_hz))
        return cls(t_rst, t_settle, R, dmd.clear_row_cycles * R, dmd.rows, max(R, row_period or R))

    @property
    def settle_path(self):
        """The shortest plane of PWM: RST_ACTIVE, the settle time, then one block clear."""
        return self.t_rst + self.t_settle + self.clear

    @property
    def load(self):
        """One plane's rows on the bus, a row every ``row_period`` cycles, the last a row cycle."""
        return (self.rows - 1) * self.row_period + self.row


@dataclass(frozen=True)
class Bound:
    """The shortest frame of a scheme at ``depth`` bits (``dmd`` cycles) and what binds it; ``k``:
    the low bits of a two-DMD split, ``lsb``: a gated frame's least significant light pulse."""
    scheme: str
    depth: int
    frame_cycles: int
    binds: str
    k: int | None = None
    lsb: int | None = None

    @property
    def rate_hz(self):
        return FABRIC_HZ / self.frame_cycles


def one(paces, depth):
    """Binary-weighted PWM on one DMD: ``2**depth - 1`` settle paths, or ``depth`` loads a frame
    on the bus if those take longer (``binds``: ``lsb`` or ``loads``). The loads are every row of
    every plane: a frame with light in every block of every plane (the sequencer clears a block
    a plane leaves dark instead of loading its rows, so a sparser frame may load less)."""
    pwm = (2 ** depth - 1) * paces.settle_path
    loads = depth * paces.rows * paces.row_period
    return Bound("one", depth, max(pwm, loads), "lsb" if pwm >= loads else "loads")


def gate_lead(lead="settle"):
    """Cycles from a pulse to the mirrors settled, by :data:`LEADS` name."""
    return math.ceil(sum(TIMING[name].value for name in LEADS[lead]) * FABRIC_HZ - 1e-9)


def _edge():
    """Cycles of the source's slower edge (:data:`spec.facts.LIGHT`): the light is off this long
    after the gate falls, and at full light this long after it rises."""
    return math.ceil(max(LIGHT["t_rise"].value, LIGHT["t_fall"].value) * FABRIC_HZ - 1e-9)


#: The shortest light pulse of a gated frame, by name: ``cycle`` one ``dmd`` cycle (the gate's
#: resolution), ``edges`` the source's rise and fall (a shorter pulse never reaches full light,
#: so its light is not its length's share).
SHORTEST = {"cycle": lambda: 1, "edges": lambda: 2 * _edge()}


def plane_time(paces, depth, lead="settle", shortest="cycle"):
    """A gated plane's time ``T`` at ``depth`` bits and what binds it: a global-reset binary
    pattern's (``reload``: ``t_rst + t_settle``, then the next plane's rows), or, if longer, the
    lead, the longest light pulse (``2**(depth - 1)`` of the shortest, :data:`SHORTEST`) and the
    source's edge before the next pulse (``gate``)."""
    reload = paces.t_rst + paces.t_settle + paces.load
    gate = gate_lead(lead) + (2 ** (depth - 1)) * SHORTEST[shortest]() + _edge()
    return (reload, "reload") if reload >= gate else (gate, "gate")


def gated(paces, depth, lead="settle", shortest="cycle"):
    """Every plane for ``T``, the source on for ``lsb << e`` from the lead on, off a source edge
    before the next pulse: ``depth * T``."""
    T, binds = plane_time(paces, depth, lead, shortest)
    lsb = (T - gate_lead(lead) - _edge()) // 2 ** (depth - 1)
    return Bound("gated", depth, depth * T, binds, lsb=lsb)


def _split(depth):
    """The low bits of the best two-DMD split: ``max(k, depth - k)`` least, the fewer bits on
    the dim board."""
    return depth // 2


def dual(paces, depth):
    """Two DMDs, ``depth - k`` and ``k`` bits at one LSB: one DMD's bound at ``max(k, depth - k)``."""
    k = _split(depth)
    inner = one(paces, max(k, depth - k))
    return Bound("dual", depth, inner.frame_cycles, inner.binds, k=k)


def dual_gated(paces, depth, lead="settle", shortest="cycle"):
    """Both boards gated: ``max(k, depth - k)`` planes of ``T``."""
    k = _split(depth)
    inner = gated(paces, max(k, depth - k), lead, shortest)
    return Bound("dual_gated", depth, inner.frame_cycles, inner.binds, k=k, lsb=inner.lsb)


#: The schemes, by the name the figures use.
SCHEMES = {"one": one, "gated": gated, "dual": dual, "dual_gated": dual_gated}


def sequence_frames(dmd, depth, memory="atlys_ddr2"):
    """Frames of ``depth`` planes a memory of :data:`MEMORIES` holds, each plane as the store lays
    it out (``rows`` rows of ``columns / 64`` words of 8 bytes)."""
    plane_bytes = dmd.rows * dmd.words_per_row * 8
    return int(MEMORY[MEMORIES[memory]].value) // (depth * plane_bytes)
