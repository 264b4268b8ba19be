"""Grey levels at a bit depth: what a frame of depth ``d`` shows, and the host's rounding to it.

What the projector shows
------------------------
A frame of bit depth ``d`` (1..8, a control record's ``bit_depth``) keeps the ``d`` most
significant bits of each pixel byte sent (bit-planes ``8 - d`` .. 7) and shows the ``d``-bit
level ``q`` they form by binary-weighted PWM: the plane of weight ``2**e`` is lit for
``lsb << e`` cycles, so level ``q`` sends ``q * lsb`` cycles of light and the frame's full scale
(every plane lit) is ``(2**d - 1) * lsb``. In 8-bit LSB of full scale, level ``q`` shows

    shown(q, d) = q * 255 / (2**d - 1)

exactly: 0 and 255 at every depth, the steps ``255 / (2**d - 1)`` apart (255 at depth 1, 17 at
depth 4, 1 at depth 8). The low ``8 - d`` bits of a byte are not stored.

The host's rounding
-------------------
A target image (8-bit, or real values in 0..255) is shown at depth ``d`` by the nearest level,
``q = floor(x * (2**d - 1) / 255 + 1/2)``, never by cutting the low bits (which shows a pixel of
value 15 at depth 4 as black, and biases depth 1 by half its range). The byte sent for ``q`` is
``floor(q * 255 / (2**d - 1))``: its top ``d`` bits are ``q``, and read as an 8-bit image it is
within one LSB below what the projector shows (for ``d`` = 1, 2, 4, 8 it is exactly that).

:func:`quantise` picks the smallest depth whose rounding leaves every pixel within a tolerance
of its target (default half an 8-bit LSB: an 8-bit image then goes at the depth its values
need, and exactly), and reports the error left, in 8-bit LSB.
"""

from dataclasses import dataclass

import numpy as np

__all__ = ["DEPTHS", "FULL_SCALE", "shown", "levels", "encode", "Quantised", "quantise"]

#: Bit depths the projector shows.
DEPTHS = range(1, 9)
#: Full scale in 8-bit LSB.
FULL_SCALE = 255


def _steps(depth):
    if depth not in DEPTHS:
        raise ValueError(f"bit depth {depth} is not 1..8")
    return (1 << depth) - 1


def shown(level, depth):
    """8-bit LSB of full scale that level ``level`` of a ``depth``-bit frame shows (float)."""
    return np.asarray(level, dtype=np.float64) * FULL_SCALE / _steps(depth)


def levels(target, depth):
    """The nearest ``depth``-bit level to each target value (8-bit LSB, 0..255): ``uint8``."""
    x = np.asarray(target, dtype=np.float64)
    if x.size and (np.isnan(x).any() or x.min() < 0 or x.max() > FULL_SCALE):
        raise ValueError("target values must lie in 0..255")
    return np.floor(x * _steps(depth) / FULL_SCALE + 0.5).astype(np.uint8)


def encode(level, depth):
    """The bytes to send for ``depth``-bit levels: the level in the top ``depth`` bits, the low
    bits continuing it (``floor(q * 255 / (2**depth - 1))``)."""
    q = np.asarray(level, dtype=np.uint32)
    return (q * FULL_SCALE // _steps(depth)).astype(np.uint8)


@dataclass
class Quantised:
    """A target image rounded to a bit depth.

    Attributes
    ----------
    depth : int
        Bit depth to show it at (the control record's ``bit_depth``).
    data : numpy.ndarray
        ``uint8`` bytes to send (top ``depth`` bits: the levels).
    levels : numpy.ndarray
        ``uint8`` levels, 0 .. ``2**depth - 1``.
    error_lsb : float
        Largest ``|shown - target|`` over the image, in 8-bit LSB.
    """
    depth: int
    data: np.ndarray
    levels: np.ndarray
    error_lsb: float


def _errors(values):
    """Largest rounding error at each depth over ``values`` (a 1-D array of distinct targets)."""
    return {d: float(np.abs(shown(levels(values, d), d) - values).max(initial=0.0)) for d in DEPTHS}


def _distinct(image):
    """The distinct values of an image (cheap for 8-bit images: a histogram)."""
    if image.dtype == np.uint8:
        return np.flatnonzero(np.bincount(image.reshape(-1), minlength=256)).astype(np.float64)
    return np.unique(image.astype(np.float64))


def quantise(image, depth=None, *, tolerance=0.5):
    """Round a target image (2-D, 8-bit or real values in 0..255) to a bit depth.

    Parameters
    ----------
    image : array_like
        Targets in 8-bit LSB of full scale.
    depth : int, optional
        Show it at this depth; default: the smallest depth at which no pixel is further than
        ``tolerance`` from its target (8 when none is).
    tolerance : float
        Largest error, in 8-bit LSB, the choice of depth accepts.

    Returns
    -------
    Quantised
    """
    image = np.asarray(image)
    if image.ndim != 2:
        raise ValueError(f"need a 2-D image, got shape {image.shape}")
    if depth is not None:
        _steps(depth)
    errors = _errors(_distinct(image))
    if depth is None:
        depth = next((d for d in DEPTHS if errors[d] <= tolerance), DEPTHS[-1])
    q = levels(image, depth)
    return Quantised(depth=depth, data=encode(q, depth), levels=q, error_lsb=errors[depth])
