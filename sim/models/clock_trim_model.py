"""Model of a board's self-calibrating clock (:class:`gateware.sync.clock_trim.ClockTrim`),
written from its description, in plain integers.

:class:`ClockTrimModel` takes the time base's value at each pulse the detector saw and gives the
phase, the trim word and the counts the gateware must show. :func:`lock` runs the loop against
an oscillator in continuous phase (a VCXO of ``ppm`` error, ``step_ppb`` a trim step, pulses
every ``period`` nominal cycles), the experiment that chose the gains: with
``kp = 23 - bit_length(period)`` and ``ki = kp - 4`` the edge settles within a tenth of a cycle
of the falling edge in under 100 pulses, from 1,500 to 730,000 cycles a period, for crystals up
to 100 ppm off.
"""

import math

__all__ = ["ClockTrimModel", "lock", "loop_gains"]

CAPTURE = 1024
LOCK_PULSES = 15
TERM = 15


def loop_gains(period):
    kp = min(max(23 - period.bit_length(), 0), 15)
    return kp, max(kp - 4, 0)


def _clamp(value, bits=TERM):
    top = (1 << (bits - 1)) - 1
    return max(-top - 1, min(top, value))


class ClockTrimModel:
    """The loop, pulse by pulse."""

    def __init__(self, period):
        self.period = period
        self.kp, self.ki = loop_gains(period)
        self.expected = None
        self.integral = 0
        self.trim = 0
        self.phase = 0
        self.good = 0
        self.crossings = 0
        self.side = 0
        self.pulses = 0
        self.slips = 0

    def pulse(self, now):
        """A pulse seen when the time base read ``now``; returns the trim word after it."""
        self.pulses += 1
        if self.expected is None:
            self.expected = (now + (now & 1) + self.period) & 0xFFFF
            return self.trim
        phase = (now - self.expected) & 0xFFFF
        self.phase = phase - 0x10000 if phase & 0x8000 else phase
        self.expected = (self.expected + self.period) & 0xFFFF
        if not -CAPTURE <= self.phase < CAPTURE:
            self.slips += 1
            self.expected = None
            self.good = self.crossings = 0
            return self.trim
        error = -(2 * self.phase + 1)
        if self.phase in (0, -1):
            # the edge crossing the falling edge: the phase flips between 0 and -1
            if self.good and self.side != (self.phase & 1):
                self.crossings = min(self.crossings + 1, 2)
            self.side = self.phase & 1
            self.good = min(self.good + 1, LOCK_PULSES)
        else:
            self.good = self.crossings = 0
        self.integral = _clamp(self.integral + error)
        self.trim = _clamp(error << self.kp) + _clamp(self.integral << self.ki)
        return self.trim

    @property
    def locked(self):
        return self.good == LOCK_PULSES and self.crossings == 2


def lock(period, ppm, *, step_ppb=8, pulses=400, start=0.3):
    """The loop on a VCXO ``ppm`` off, pulses every ``period`` nominal cycles: per pulse, the
    distance (cycles) from the pulse's edge to the nearest falling edge and the VCXO's
    remaining error (ppm). ``start``: the clock's phase (cycles) at the first pulse."""
    model = ClockTrimModel(period)
    x = start            # the board's cycles elapsed, at the pulse
    out = []
    for _ in range(pulses):
        # the detector's falling edges are at x = n + 0.5; the pulse is seen at the first after it
        # (two synchroniser stages add the same to every reading)
        seen = math.floor(x - 0.5) + 1
        trim = model.pulse(seen)
        error = ppm * 1e-6 + trim * step_ppb * 1e-9
        frac = (x - 0.5) % 1.0
        out.append((min(frac, 1 - frac), error * 1e6))
        x += period * (1 + error)
    return out
