"""Where the store keeps each word in DDR2: frame slot -> plane -> row -> word.

One row of one plane is ``words_per_row`` consecutive 64-bit words, word 0 (columns 0..63)
first; the rows of a plane follow each other, so a plane is one contiguous run and streams to the
DMD with no reformatting; the 8 planes of a slot follow each other, plane 0 (least significant)
first; slots follow each other from ``base``. A slot always spans 8 planes, whatever the bit
depth of the frame in it (a 1-bit frame writes and reads plane 7 only).

Byte addresses (``word_bytes`` = 8)::

    row_bytes   = words_per_row * 8              DLP7000: 0x80     DLP9500: 0x100    test: 0x10
    plane_bytes = rows * row_bytes               DLP7000: 0x18000  DLP9500: 0x43800  test: 0x600
    slot_bytes  = 8 * plane_bytes                DLP7000: 0xC0000  DLP9500: 0x21C000 test: 0x3000
    address(slot, plane, row, word) = base + slot * slot_bytes + plane * plane_bytes
                                      + row * row_bytes + word * 8

An XGA plane is 12,288 words (0x3000 words, 0x18000 bytes) as in the seed design. The same
function computes addresses for the gateware (Amaranth values) and for the models (integers).
Every row starts on a 16-byte boundary when ``words_per_row`` is even (every DMD here), so a
128-bit memory port reads whole rows.
"""

from spec.facts import MEMORY

__all__ = ["AddressMap", "MEMORY_BYTES", "PLANES", "WORD_BYTES"]

#: The Atlys DDR2 (MT47H64M16): 64 Mi x 16 bit = 128 MiB.
MEMORY_BYTES = int(MEMORY["bytes"].value)
PLANES = 8
#: Bytes in a plane word (64 columns); the memory ports move one, two or half of one at a time.
WORD_BYTES = 8


class AddressMap:
    """Byte addresses of the store's words for one DMD geometry and ``slots`` frame slots."""

    def __init__(self, dmd, slots, *, base=0, memory_bytes=MEMORY_BYTES):
        self.dmd = dmd
        self.slots = slots
        self.base = base
        self.row_bytes = dmd.words_per_row * WORD_BYTES
        self.plane_bytes = dmd.rows * self.row_bytes
        self.slot_bytes = PLANES * self.plane_bytes
        self.end = base + slots * self.slot_bytes
        assert base % WORD_BYTES == 0
        assert self.end <= memory_bytes, \
            f"{slots} slots of {dmd.name} need {self.end} bytes, more than the {memory_bytes} of the memory"

    def address(self, slot, plane, row=0, word=0):
        """Byte address of a word; ``slot``, ``plane``, ``row``, ``word`` ints or Amaranth values."""
        return (self.base + slot * self.slot_bytes + plane * self.plane_bytes
                + row * self.row_bytes + word * WORD_BYTES)

    def slot_range(self, slot):
        """``(first, end)`` byte addresses of a slot."""
        first = self.address(slot, 0)
        return first, first + self.slot_bytes
