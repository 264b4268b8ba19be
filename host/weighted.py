"""Two DMDs in weighted light: an n-bit frame (n <= 16) as two frames of at most 8 bits.

Board A, lit at full intensity, shows the high ``n - k`` bits of each pixel; board B, lit at
``2**-k`` of A's intensity, shows the low ``k`` bits; the two images are added optically, pixel
for pixel. Both boards play the same plan, a ``max(k, n - k)``-bit frame with the same least
significant plane (``lsb``), started together by the sync master: an n-bit frame takes the time
of a ``max(k, n - k)``-bit one. The board of fewer bits shows them as the low levels of that
depth (its upper planes dark), so that both schedules are the same.

In units of the n-bit LSB, a pixel shows ``2**k * high + ratio * low``, where ``ratio`` is B's
real intensity relative to ``2**-k`` of A's (1 when the attenuation is exact). The trim
(:func:`measure`, :func:`trim`) reads a flat field from each board alone and lengthens the planes
of the board that is too dim (its sequence entries' ``lsb``, even cycles; never shorter than the
plan's), so that the ratio is 1 to within the sequencer's two-cycle step.

Plain Python and numpy (layers: host imports spec only).
"""

from dataclasses import dataclass, replace

import numpy as np

from spec import plan_search, schedule
from spec.registers import TriggerMode

from . import levels

__all__ = ["MAX_BITS", "low_bits_range", "default_low_bits", "depth_of", "split", "combine", "board_bytes",
           "DualPlan", "plan", "fastest", "measure", "Trim", "trim", "trimmed_frame_cycles", "ENTRY_LSB_MAX"]

#: The deepest frame two boards of 8 bits each show.
MAX_BITS = 16
#: The longest least significant plane a sequence entry holds (its ``lsb`` field, 24 bits).
ENTRY_LSB_MAX = (1 << 24) - 2


def low_bits_range(bits):
    """The low bits board B may show of a ``bits``-bit frame: each board shows 1 to 8."""
    if not 2 <= bits <= MAX_BITS:
        raise ValueError(f"a weighted frame has 2 to {MAX_BITS} bits, not {bits}")
    return range(max(1, bits - 8), min(8, bits - 1) + 1)


def default_low_bits(bits):
    """``bits // 2``: the split whose frame is the shortest."""
    return bits // 2


def depth_of(bits, low_bits):
    """The bit depth both boards play: the larger of their parts."""
    if low_bits not in low_bits_range(bits):
        raise ValueError(f"{low_bits} low bits of a {bits}-bit frame: each board shows 1 to 8 bits")
    return max(low_bits, bits - low_bits)


def split(image, bits, low_bits=None):
    """An n-bit image (``uint16``, values below ``2**bits``) -> (board A's high ``bits - k``
    bits, board B's low ``k`` bits), each ``uint16``."""
    k = default_low_bits(bits) if low_bits is None else low_bits
    depth_of(bits, k)
    image = np.asarray(image)
    if not np.issubdtype(image.dtype, np.unsignedinteger):
        raise ValueError(f"need an unsigned integer image, got {image.dtype}")
    if image.size and int(image.max()) >> bits:
        raise ValueError(f"values above {(1 << bits) - 1} in a {bits}-bit image")
    image = image.astype(np.uint16)
    return image >> k, image & ((1 << k) - 1)


def combine(high, low, low_bits, ratio=1.0):
    """What the two boards show together, in n-bit LSB (float): ``2**k * high + ratio * low``."""
    return np.asarray(high, np.float64) * (1 << low_bits) + ratio * np.asarray(low, np.float64)


def board_bytes(values, depth):
    """A board's levels (below ``2**depth``) as the bytes sent for a ``depth``-bit frame
    (:func:`host.levels.encode`: the level in the top ``depth`` bits)."""
    values = np.asarray(values)
    if values.size and int(values.max()) >> depth:
        raise ValueError(f"levels above {(1 << depth) - 1} at depth {depth}")
    return levels.encode(values, depth)


@dataclass
class DualPlan:
    """Both boards' plan: ``plan`` (a :class:`spec.schedule.Plan` at :attr:`depth` bits), for
    ``bits``-bit frames split at ``low_bits``."""
    bits: int
    low_bits: int
    plan: object

    @property
    def depth(self):
        return depth_of(self.bits, self.low_bits)

    @property
    def high_bits(self):
        return self.bits - self.low_bits

    @property
    def rate_hz(self):
        return self.plan.rate_hz

    @property
    def lsb(self):
        return self.plan.params.lsb

    def weights(self):
        """Each board's light intensity relative to board A's: ``{"a": 1, "b": 2**-k}``."""
        return {"a": 1.0, "b": 2.0 ** -self.low_bits}

    def params(self, sync_period=0):
        """Both boards' :class:`spec.schedule.Params`: the plan's, started by the sync input
        (``sync_period``: the master's period in nominal cycles, for the clock loop; 0: off)."""
        return replace(self.plan.params, trigger=TriggerMode.SYNC, period=sync_period)

    def board_params(self, board, trimmed=None, sync_period=0):
        """Board ``board``'s (``"a"`` or ``"b"``) :meth:`params`, its ``lsb`` the trim's
        (``trimmed``, a :class:`Trim`) when the board's frame is shown alone, not by a sequence's
        entries."""
        p = self.params(sync_period)
        if trimmed is not None:
            p = replace(p, lsb=trimmed.lsb_a if board == "a" else trimmed.lsb_b)
        return p

    def registers(self, dmd, sync_period=0):
        """Each board's sequencer registers (the same for both): ``{"a": dict, "b": dict}``."""
        regs = self.params(sync_period).registers(dmd)
        return {"a": regs, "b": dict(regs)}

    def images(self, image):
        """An n-bit image -> each board's bytes at :attr:`depth`: ``{"a": uint8, "b": uint8}``."""
        high, low = split(image, self.bits, self.low_bits)
        return {"a": board_bytes(high, self.depth), "b": board_bytes(low, self.depth)}


def plan(dmd, dclk_hz, bits, low_bits=None, *, best=False, **plan_kwargs):
    """The :class:`DualPlan` of ``bits``-bit frames split at ``low_bits`` (default
    :func:`default_low_bits`): :func:`spec.schedule.plan` at the depth of the larger part, or
    with ``best`` the plan finder's fastest (:func:`spec.plan_search.find`)."""
    k = default_low_bits(bits) if low_bits is None else low_bits
    depth = depth_of(bits, k)
    if best:
        found = plan_search.find(dmd, dclk_hz, depth=depth, **plan_kwargs).plan
    else:
        found = schedule.plan(dmd, dclk_hz, depth=depth, **plan_kwargs)
    return DualPlan(bits, k, found)


def fastest(dmd, dclk_hz, bits, **plan_kwargs):
    """The split of the fastest frame (of equal ones, the fewest low bits): a :class:`DualPlan`."""
    plans = [plan(dmd, dclk_hz, bits, k, **plan_kwargs) for k in low_bits_range(bits)]
    return min(plans, key=lambda p: (p.plan.frame_cycles, p.low_bits))


def measure(reading_a, reading_b, *, level_a, level_b, low_bits, lsb_a, lsb_b, dark=0.0):
    """Board B's intensity relative to ``2**-k`` of board A's, less 1 (the ratio error), from a
    flat field: ``reading_a`` what the sensor read (any unit, an array over the field or a
    number) with board A at level ``level_a`` and B dark, ``reading_b`` with B at ``level_b``
    and A dark, ``dark`` with both dark; each board's planes ``lsb_a``, ``lsb_b`` cycles."""
    a = float(np.mean(reading_a)) - float(np.mean(dark))
    b = float(np.mean(reading_b)) - float(np.mean(dark))
    if a <= 0 or level_a <= 0 or level_b <= 0:
        raise ValueError("the flat field must light board A, and both levels must be above 0")
    per_a = a / (level_a * lsb_a)
    per_b = b / (level_b * lsb_b)
    return per_b / per_a * (1 << low_bits) - 1


def _even(x):
    return 2 * int(np.floor(x / 2 + 0.5))


@dataclass
class Trim:
    """The least significant planes that make B's light ``2**-k`` of A's: ``lsb_a``, ``lsb_b``
    (cycles, even; the dim board's lengthened, the other's the plan's); ``residual`` the ratio
    error left by the two-cycle step."""
    lsb_a: int
    lsb_b: int
    residual: float

    def entry_lsb(self, board, plan_lsb):
        """The sequence entries' ``lsb`` of ``board`` (``"a"`` or ``"b"``): 0 where it is the
        register's."""
        lsb = self.lsb_a if board == "a" else self.lsb_b
        return 0 if lsb == plan_lsb else lsb


def trim(dual, error, dmd=None):
    """The :class:`Trim` for a ratio error ``error`` (:func:`measure`) of ``dual`` (a
    :class:`DualPlan`): B too dim (``error`` < 0) gets planes ``1 / (1 + error)`` as long, A too
    dim (B too bright) ``1 + error`` as long, each rounded to even cycles and never shorter than
    the plan's. With ``dmd``, the lengthened board's frame is checked against the schedule model
    (no pulse late)."""
    if not error > -1:
        raise ValueError(f"ratio error {error}: board B gives no light")
    lsb = dual.lsb
    lsb_a, lsb_b = lsb, lsb
    if error < 0:
        lsb_b = max(lsb, _even(lsb / (1 + error)))
    else:
        lsb_a = max(lsb, _even(lsb * (1 + error)))
    if max(lsb_a, lsb_b) > ENTRY_LSB_MAX:
        raise ValueError(f"a trimmed plane of {max(lsb_a, lsb_b)} cycles does not fit a sequence entry")
    if dmd is not None:
        longer = max(lsb_a, lsb_b)
        if longer != lsb and not schedule.on_time(dmd, dual.plan.params,
                                                  schedule.Frame(0, dual.depth, lsb=longer, sequence=True)):
            raise ValueError(f"planes of {longer} cycles make pulses late under the plan")
    return Trim(lsb_a, lsb_b, (1 + error) * lsb_b / lsb_a - 1)


def trimmed_frame_cycles(dual, trimmed, dmd):
    """The frame period of the two boards trimmed (the longer board's), from the schedule model."""
    longer = max(trimmed.lsb_a, trimmed.lsb_b)
    if longer == dual.lsb:
        return dual.plan.frame_cycles
    return schedule.frame_period(dmd, dual.plan.params, schedule.Frame(0, dual.depth, lsb=longer, sequence=True))
