"""What the protocol hands the blocks above it: image rows as pixel beats."""

from amaranth.lib import data
from amaranth.utils import ceil_log2

__all__ = ["pixel_layout", "position_fields"]


def position_fields(dmd, frame_bits):
    """Where a beat belongs: its frame tag and row (shared by every layout that follows a row)."""
    return {
        "frame": frame_bits,
        "row": ceil_log2(dmd.rows),
    }


def pixel_layout(dmd, lanes=1, frame_bits=4):
    """One beat of an image row: ``lanes`` pixels, left to right, starting at column ``column``
    of ``row`` (the protocol parser sends one pixel per beat, the serialiser takes 1 to 8)."""
    return data.StructLayout({
        "pixels": data.ArrayLayout(8, lanes),
        "column": ceil_log2(dmd.columns),
        **position_fields(dmd, frame_bits),
    })
