"""Bit-plane slicing: 8-bit pixels in, 64-bit single-plane words out."""

from .serialiser import Serialiser, row_flags_layout, word_layout

__all__ = ["Serialiser", "word_layout", "row_flags_layout"]
