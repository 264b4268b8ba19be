"""What the protocol hands the blocks above it: image rows as pixel beats."""

from amaranth.lib import data
from amaranth.utils import ceil_log2

__all__ = ["pixel_layout", "position_fields", "piece_layout", "position_bits", "tag_fields", "TAG",
           "copy_tag"]

#: The fields of a frame tag (:func:`tag_fields`), in every layout that follows a frame.
TAG = ("frame", "base", "carried")


def tag_fields(dmd, frame_bits):
    """The frame a beat belongs to: its id and, for a delta frame, the whole frame ``base`` it
    takes the rows it does not carry from and how many rows it carries (``carried``, 0 for a whole
    frame; a count beyond the DMD's rows is kept as ``rows + 1``, for the store to refuse)."""
    return {
        "frame": frame_bits,
        "base": frame_bits,
        "carried": ceil_log2(dmd.rows + 2),
    }


def copy_tag(dst, src):
    """Assignments of ``src``'s frame tag to ``dst``'s (views with the :data:`TAG` fields)."""
    return [dst[name].eq(src[name]) for name in TAG]


def position_fields(dmd, frame_bits):
    """Where a beat belongs: its frame tag and row (shared by every layout that follows a row)."""
    return {
        **tag_fields(dmd, frame_bits),
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


def position_bits(dmd):
    """Width of a pixel's position in its frame (``row * columns + column``) and of one past the
    frame's last pixel."""
    return ceil_log2(dmd.rows * dmd.columns + 1)


def piece_layout(dmd):
    """One pixel of an image record, from the parser to the row assembler: its byte, frame tag,
    position in the frame, where its record ends (one past the record's last pixel), and whether
    it is the record's first."""
    return data.StructLayout({
        "data": 8,
        **tag_fields(dmd, 16),
        "position": position_bits(dmd),
        "until": position_bits(dmd),
        "first": 1,
    })
