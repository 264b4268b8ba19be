"""What the row ingest and the slot table say to each other (``sync``): the ingest's question,
where a row of a frame goes (:class:`Placement`), and the news of a slot opened for a new frame.

The table decides (:mod:`gateware.store.slot_table`) and the ingest acts on the answer in the
same cycle; the terms they share live here, apart from either, so that the ingest needs nothing
of the table but them.
"""

from amaranth.lib import data, enum, wiring
from amaranth.lib.wiring import In, Out

from .layouts import SLOT_BITS

__all__ = ["Placement", "PlacementSignature", "opening_layout"]


class Placement(enum.Enum, shape=4):
    """Where a row of a frame goes (a row number beyond the frame is the ingest's own refusal,
    checked after ``HOLD`` and before the others)."""
    HOLD = 0          # a change of mode is pending: nothing is decided before it
    JOIN = 1          # the slot receiving this frame
    TAKE = 2          # a free slot, for a new frame
    ABANDON = 3       # the receiving slot, taken from an older frame that is not complete
    WAIT = 4          # no slot now; one frees when the frame being written is ready
    STALE = 5         # refused: older than the frame receiving, or not in the sequence
    SHOWN = 6         # refused: the frame of a slot being shown
    DUPLICATE = 7     # refused: the frame's slot is complete (sequence)
    NO_SLOT = 8       # refused: the sequencer holds every other slot
    NO_BASE = 9       # refused: a delta whose base is not a whole frame held


class PlacementSignature(wiring.Signature):
    """The ingest's question to the slot table, seen from the ingest (``sync``).

    Members
    -------
    frame : Out(frame_bits)
        Frame id of the row to place.
    delta, base : Out(1), Out(frame_bits)
        The frame is a delta of frame ``base``.
    between_rows : Out(1)
        The ingest waits for a row's first word: a change of mode may be applied.
    verdict : In(Placement)
        Where the row goes, at once.
    slot : In(SLOT_BITS)
        The slot for ``JOIN``, ``TAKE`` and ``ABANDON``.
    depth : In(4)
        The bit depth of the frame in that slot (for ``JOIN``).
    base_slot, base_depth : In(SLOT_BITS), In(4)
        A delta's base: its slot and bit depth (for ``TAKE`` and ``ABANDON``).
    """

    def __init__(self, frame_bits):
        self._frame_bits = frame_bits
        super().__init__({
            "frame": Out(frame_bits),
            "delta": Out(1),
            "base": Out(frame_bits),
            "between_rows": Out(1),
            "verdict": In(Placement),
            "slot": In(SLOT_BITS),
            "depth": In(4),
            "base_slot": In(SLOT_BITS),
            "base_depth": In(4),
        })

    def __eq__(self, other):
        return isinstance(other, PlacementSignature) and other._frame_bits == self._frame_bits


def opening_layout(frame_bits):
    """A slot taken for a new frame: from now on it receives frame ``frame`` at ``depth`` bits,
    a delta of the frame in slot ``base`` with ``delta``."""
    return data.StructLayout({"slot": SLOT_BITS, "frame": frame_bits, "depth": 4, "delta": 1, "base": SLOT_BITS})
