"""What the store and the sequencer exchange (``dmd`` domain).

The sequencer asks for the rows of one plane of one slot and receives the words in row order,
``words_per_row`` words per row, word 0 (columns 0..63) first. It learns which frames are ready
from the store and hands a slot back once its last plane has been read for the last time.
"""

from amaranth.lib import data

__all__ = ["SLOT_BITS", "PlaneRequest", "FrameInfo"]

#: Frame slots are numbered in this many bits (16 slots; sequence mode spans slots).
SLOT_BITS = 4


class PlaneRequest(data.Struct):
    """Read ``row_count`` rows from ``first_row`` of plane ``plane`` of slot ``slot``."""
    slot: SLOT_BITS
    plane: 3
    first_row: 11
    row_count: 11


class FrameInfo(data.Struct):
    """A complete frame the sequencer may show."""
    slot: SLOT_BITS
    frame_id: 16
    bit_depth: 4      # 1..8 planes stored, most significant first: planes 8-bit_depth..7
