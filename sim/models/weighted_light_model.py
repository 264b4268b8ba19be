"""Two DMDs in weighted light: what a sensor sees of both boards' images added optically.

Written from ``docs/weighted_light.md``, independent of the gateware and of ``host.weighted``.
Board A is lit at full intensity, board B at ``2**-k`` of it times ``1 + ratio_error`` (the
attenuator's real value). Each board's light over a window comes from its own pins (the camera
model on its mirrors, in units of its least significant plane: the board's grey level); the
window is the same real-time span for both, so a board that starts late or runs slow gives the
light it gave in that span. In units of the n-bit LSB a pixel shows

    2**k * light_a + (1 + ratio_error) * light_b.

The sync error between the boards is read from their clocking pulses' times on the pins: the
j-th pulse of a frame on A against the j-th on B.
"""

import numpy as np

__all__ = ["grey", "sync_errors_ns", "flat_readings"]


def grey(light_a, light_b, low_bits, ratio_error=0.0):
    """Both boards' light (each in its own least significant plane's units) -> n-bit LSB."""
    return (2.0 ** low_bits) * np.asarray(light_a, np.float64) + \
        (1.0 + ratio_error) * np.asarray(light_b, np.float64)


def sync_errors_ns(pulses_a, pulses_b, syncs):
    """Per frame (the span from one sync pulse to the next, ``syncs`` in ps) the time (ns) of
    each of B's clocking pulses less A's (``pulses_*``: arrays of pulse times in ps), for the
    frames in which both made as many pulses: a list of arrays."""
    out = []
    for k in range(len(syncs)):
        end = syncs[k + 1] if k + 1 < len(syncs) else np.inf
        a = pulses_a[(pulses_a >= syncs[k]) & (pulses_a < end)]
        b = pulses_b[(pulses_b >= syncs[k]) & (pulses_b < end)]
        if len(a) and len(a) == len(b):
            out.append((b - a) / 1000.0)
    return out


def flat_readings(light_a, light_b, low_bits, ratio_error=0.0, *, gain=1.0):
    """What a sensor reads of a flat field with one board lit at a time: (A alone, B alone),
    each the mean over the field of the board's light times its intensity (A 1, B ``2**-k (1 +
    ratio_error)``) times the sensor's ``gain``."""
    a = gain * float(np.mean(light_a))
    b = gain * float(np.mean(light_b)) * 2.0 ** -low_bits * (1.0 + ratio_error)
    return a, b
