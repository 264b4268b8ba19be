"""The small DMD the formal checks build the store and the protocol for.

One 64-bit word per row and 16 rows (the fewest the frame slots take: one occupancy block per
row at most) in two blocks: a frame is 128 words, so a solver sees frames complete, shown and
released within a few hundred cycles. No property checked here depends on the geometry.
"""

import dataclasses

from spec.facts import TEST_DMD

__all__ = ["FORMAL_DMD"]

FORMAL_DMD = dataclasses.replace(TEST_DMD, name="formal 64x16", columns=64, rows=16, visible_columns=64,
                                 blocks=2, rows_per_block=8)
