"""Reference model of bit-plane slicing (numpy), the oracle for the serialiser and the store.

Conventions are those of :mod:`gateware.bitplane.serialiser`: plane ``k`` holds bit ``k`` of each
pixel; word ``w`` of a row holds columns ``64w .. 64w+63``, column ``64w + i`` in bit ``i``.
"""

import numpy as np

PLANES = 8


def planes(image):
    """``image`` (rows, columns) uint8 -> (8, rows, columns) array of 0/1, plane 0 = LSB."""
    image = np.asarray(image, dtype=np.uint8)
    return np.stack([(image >> k) & 1 for k in range(PLANES)]).astype(np.uint8)


def plane_words(image):
    """(8, rows, columns // 64) array of uint64 words, bit i = column 64w + i."""
    bits = planes(image)
    p, rows, cols = bits.shape
    packed = np.packbits(bits.reshape(p, rows, cols // 64, 64), axis=-1, bitorder="little")
    return packed.view("<u8").reshape(p, rows, cols // 64)


def row_flags(image):
    """(rows,) uint8: bit k set when any pixel of the row has bit k set."""
    image = np.asarray(image, dtype=np.uint8)
    return np.bitwise_or.reduce(image, axis=1)


def occupancy(image, rows_per_block):
    """(blocks,) uint8: bit k set when plane k has any bit set in the block."""
    flags = row_flags(image)
    return np.bitwise_or.reduce(flags.reshape(-1, rows_per_block), axis=1)


def image_from_words(words):
    """Inverse of :func:`plane_words`: (8, rows, words) uint64 -> (rows, columns) uint8."""
    words = np.asarray(words, dtype="<u8")
    p, rows, nw = words.shape
    bits = np.unpackbits(words.view(np.uint8).reshape(p, rows, nw, 8), axis=-1, bitorder="little")
    bits = bits.reshape(p, rows, nw * 64)
    return sum((bits[k].astype(np.uint16) << k) for k in range(p)).astype(np.uint8)


def extreme_images(rows, columns, seed=0):
    """The images every bit-plane test runs besides random ones, by name."""
    rng = np.random.default_rng(seed)
    yy, xx = np.mgrid[0:rows, 0:columns]
    one_pixel = np.zeros((rows, columns), np.uint8)
    one_pixel[rows // 3, columns - 1] = 1
    per_plane = np.zeros((rows, columns), np.uint8)
    for k in range(PLANES):   # one pixel per plane, each in another block and word
        per_plane[(k * rows) // PLANES, (k * 67) % columns] = 1 << k
    return {
        "zeros": np.zeros((rows, columns), np.uint8),
        "full": np.full((rows, columns), 255, np.uint8),
        "one_pixel": one_pixel,
        "checker": (((yy + xx) & 1) * 255).astype(np.uint8),
        "checker_alt": (((yy + xx) & 1) * 0xAA + ((yy + xx + 1) & 1) * 0x55).astype(np.uint8),
        "one_per_plane": per_plane,
        "random": rng.integers(0, 256, (rows, columns), dtype=np.uint8),
    }
