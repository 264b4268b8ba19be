"""What the store and the sequencer exchange (all in the ``dmd`` domain).

Frames
------
The sequencer learns of showable frames by asking: each transfer on the store's ``ask`` port
asks for one frame, and the store answers on ``frames`` with a :class:`FrameInfo` as soon as it
has one to give: in streaming mode the newest complete frame (an older one that was never given
out is replaced and counted), in sequence mode the next slot of the sequence, in order. From the
answer on, the slot is *shown*: the store never writes it until the sequencer hands it back on
``release`` (in streaming mode the slot is then free for a new frame; in sequence mode it stays
in the sequence). A sequencer that wants the newest frame at each frame boundary asks at the
boundary; one that wants no gap keeps one ask outstanding.

Planes
------
The sequencer asks for the rows of one plane of a slot it holds with a :class:`PlaneRequest`
and receives the words in row order, ``words_per_row`` words per row, word 0 (columns 0..63)
first, ``row_count * words_per_row`` words per request, requests answered in order.

Occupancy
---------
:class:`OccupancySignature`: the sequencer puts a slot and a DMD block on the port and reads,
one ``dmd`` cycle later, which planes have any bit set in that block, so that it can clear an
empty block instead of loading it. The map of a slot is written only while the slot receives
and is stable from the moment the slot is complete, long before the slot can be given to the
sequencer, so reading it from another clock domain is safe for every slot the sequencer holds.
"""

from amaranth import Mux
from amaranth.lib import data, wiring
from amaranth.lib.wiring import In, Out

__all__ = ["COUNTER_BITS", "SLOT_BITS", "LIVE_SLOTS", "BLOCK_BITS", "SHOW_BITS", "PlaneRequest", "Showing", "FrameInfo",
           "OccupancySignature"]

#: Width of every event counter: that of the status reply's fields, so that none wraps inside
#: its field (at 65,536 a 16-bit count of frames shown wrapped after minutes).
COUNTER_BITS = 32
#: Frame slots are numbered in this many bits: a stored sequence spans every slot the memory
#: holds (170 XGA frames in 128 MiB), that of the entry record's slot field.
SLOT_BITS = 8
#: The slots streaming uses, and delta frames and their bases: the store searches their states
#: every cycle, so they are kept in registers (the sequence slots beyond them are looked up by
#: number, their states in memory).
LIVE_SLOTS = 16
#: DMD blocks are numbered in this many bits (16 blocks at most).
BLOCK_BITS = 4


class PlaneRequest(data.Struct):
    """Read ``row_count`` rows from ``first_row`` of plane ``plane`` of slot ``slot``."""
    slot: SLOT_BITS
    plane: 3
    first_row: 11
    row_count: 11


#: Width of a sequence entry's times (``dmd`` cycles: 84 ms).
SHOW_BITS = 24


class Showing(data.Struct):
    """How a sequence entry shows its frame; all zero: as the sequencer's registers say."""
    lsb: SHOW_BITS    # the least significant plane's time, even (0: the register's)
    dark: SHOW_BITS   # at least this long dark after the frame before a frame that follows it
    follow: 1         # starts as soon as the frame before it ends (its dark time), no trigger
    camera_off: 1     # no camera trigger for it
    last: 1           # the last entry of a sequence played once: nothing follows it, and
                      # triggers after it starts are ignored (counted)

    def lsb_or(self, register):
        """The least significant plane's time the entry shows its frame with: its own, or the
        register's (``register``) when it gives none (0)."""
        return Mux(self.lsb != 0, self.lsb, register)


class FrameInfo(data.Struct):
    """A complete frame the sequencer may show. A frame of a stored sequence (``sequence``) is
    the next one to show, in order; a streamed one is the newest, which replaces a frame
    waiting for its trigger. ``showing``: its sequence entry's settings. It is shown as a
    ``bit_depth``-bit image of the slot's stored planes ``low_plane .. low_plane + bit_depth - 1``
    (a frame of depth d is stored in planes 8-d..7; a sequence entry may show some of them)."""
    slot: SLOT_BITS
    frame_id: 16
    bit_depth: 4      # 1..8 planes shown
    sequence: 1
    showing: Showing
    low_plane: 3      # the stored plane of its least significant plane shown


class OccupancySignature(wiring.Signature):
    """Read port of the occupancy map, seen from the sequencer (``dmd`` domain).

    Members
    -------
    slot, block : Out
        Which slot and DMD block to look up.
    planes : In(8)
        One cycle later: bit ``k`` set when plane ``k`` of that block has any bit set.
    """

    def __init__(self):
        super().__init__({
            "slot": Out(SLOT_BITS),
            "block": Out(BLOCK_BITS),
            "planes": In(8),
        })

    def __eq__(self, other):
        return isinstance(other, OccupancySignature)
