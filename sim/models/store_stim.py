"""Stimulus and checks for the bit-plane store, shared by the Amaranth and cocotb tests.

What the store must hold, by numpy: the planes of an image at a bit depth, the occupancy map,
and the address ranges a run may write (:class:`gateware.store.addresses.AddressMap`).
"""

import numpy as np

from gateware.store.addresses import PLANES, AddressMap
from . import bitplane, serialiser_stim


def stored_planes(depth):
    """Planes a frame of ``depth`` bits stores, least significant first."""
    return list(range(PLANES - depth, PLANES))


def frame_beats(image, frame_id, lanes=8, rows=None):
    """Pixel transfers of ``image`` tagged ``frame_id``; ``rows`` the row order (default all)."""
    return list(serialiser_stim.pixel_beats(image, lanes, frame=frame_id, row_order=rows))


def random_image(dmd, seed):
    return np.random.default_rng(seed).integers(0, 256, (dmd.rows, dmd.columns), dtype=np.uint8)


def check_plane(dmd, image, plane, words, first_row=0, row_count=None, what=""):
    """``words`` (read back in order) against numpy's slicing of ``image``."""
    row_count = dmd.rows if row_count is None else row_count
    want = bitplane.plane_words(image)[plane, first_row:first_row + row_count].reshape(-1)
    got = np.array([int(w) for w in words], dtype=np.uint64)
    assert got.shape == want.shape, f"{what} plane {plane}: {got.size} words read, {want.size} expected"
    bad = np.flatnonzero(got != want)
    assert bad.size == 0, (f"{what} plane {plane}: {bad.size} words differ from numpy, first at "
                           f"row {first_row + bad[0] // dmd.words_per_row} word {bad[0] % dmd.words_per_row}")


def check_occupancy(dmd, image, depth, got, what=""):
    """``got[block]`` (8-bit plane flags read from the map) against numpy's occupancy, restricted
    to the planes the frame stores (the others read as 0)."""
    keep = sum(1 << p for p in stored_planes(depth))
    want = bitplane.occupancy(image, dmd.rows_per_block) & keep
    got = np.array(got, dtype=np.uint8)
    assert np.array_equal(got, want), f"{what} occupancy {got.tolist()} != numpy {want.tolist()}"


def check_writes_inside(model, dmd, slots, allowed, since=0):
    """Every word the memory took (from ``since`` in its write log) lies in an ``allowed`` slot."""
    amap = AddressMap(dmd, slots)
    ranges = [amap.slot_range(s) for s in allowed]
    for address, _port in model.write_log[since:]:
        assert any(lo <= address < hi for lo, hi in ranges), \
            f"word written at {address:#x}, outside slots {sorted(allowed)}"
