"""Stimulus and checking for the bit-plane serialiser, shared by the Amaranth and cocotb tests.

The transfers a whole image makes on the serialiser's ports, as plain dicts, and the reassembly of
what comes out into numpy arrays to compare with :mod:`sim.models.bitplane_model`.
"""

import numpy as np

from . import bitplane_model as bitplane


def pixel_beats(image, lanes, frame=0, row_order=None, base=0, carried=0):
    """Input transfers for ``image``, rows in ``row_order`` (default top to bottom), tagged as
    frame ``frame`` (a delta of ``base`` carrying ``carried`` rows when that is nonzero)."""
    rows, cols = image.shape
    for row in (range(rows) if row_order is None else row_order):
        for col in range(0, cols, lanes):
            yield {"pixels": [int(p) for p in image[row, col:col + lanes]],
                   "column": col, "row": int(row), "frame": frame, "base": base, "carried": carried}


def assemble(dmd, words, row_flags):
    """Output transfers (dicts) -> (words array, row flags array, block numbers seen per row)."""
    got = np.zeros((bitplane.PLANES, dmd.rows, dmd.words_per_row), dtype=np.uint64)
    seen = np.zeros(got.shape, dtype=np.int32)
    order_ok = True
    last = {}
    for t in words:
        key = (t["row"], t["word"])
        if t["plane"] != last.get(key, -1) + 1:
            order_ok = False
        last[key] = t["plane"]
        got[t["plane"], t["row"], t["word"]] = t["data"]
        seen[t["plane"], t["row"], t["word"]] += 1
        assert t["block"] == dmd.block_of_row(t["row"]), f"block tag wrong for row {t['row']}"
    flags = np.zeros(dmd.rows, dtype=np.int32)
    for t in row_flags:
        assert t["block"] == dmd.block_of_row(t["row"])
        flags[t["row"]] = t["planes"]
    assert order_ok, "planes of a word position did not come out 0..7 in order"
    assert (seen == 1).all(), "a word came out twice or not at all"
    return got, flags


def check(dmd, image, words, row_flags):
    got, flags = assemble(dmd, words, row_flags)
    want = bitplane.plane_words(image)
    assert np.array_equal(got, want), f"{int((got != want).sum())} words differ from numpy's slicing"
    assert np.array_equal(flags, bitplane.row_flags(image)), "row flags differ"
    block_occ = np.bitwise_or.reduce(flags.reshape(dmd.blocks, -1), axis=1)
    assert np.array_equal(block_occ, bitplane.occupancy(image, dmd.rows_per_block))
