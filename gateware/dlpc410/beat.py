"""Where each column of a row travels on the DLPC410 data buses: the one map.

One *beat* is what the core hands the DDR output registers in one ``dmd`` cycle: for a two-bus
DMD (DLP7000, DLP650LNIR) 64 bits, DIN_A(15:0) and DIN_B(15:0) on the rising and on the falling
DCLK edge. A bit-plane *word* is 64 bits that hold 64 adjacent columns of one row of one plane;
word bit ``i`` is column ``64 * w + i`` (bit 0 = leftmost column, west when NS_FLIP is low).

This table maps word bits to (bus, edge, pin). The bit-plane serialiser packs columns into words
by the first rule above; the DLPC410 model decodes pins back into columns through this table;
nothing else knows the order.

Assumption (to confirm against the DLPC410 datasheet's data-bus figure on hardware): within a
beat, rising edge before falling edge, bus A before bus B, pin 0 first; that is::

    word bits  0..15 -> DIN_A(15:0), rising edge
    word bits 16..31 -> DIN_B(15:0), rising edge
    word bits 32..47 -> DIN_A(15:0), falling edge
    word bits 48..63 -> DIN_B(15:0), falling edge

A four-bus DMD (DLP9500) takes two words per beat: the first on A/B as above, the second on C/D.
"""

__all__ = ["LANES", "word_to_lanes", "lanes_to_word", "beat_lanes", "cycle_lanes", "PINS_PER_BUS"]

PINS_PER_BUS = 16

#: (bus, edge, first word bit) for each 16-bit lane of a 64-bit word, in word-bit order.
LANES = (
    ("A", "rise", 0),
    ("B", "rise", 16),
    ("A", "fall", 32),
    ("B", "fall", 48),
)


def beat_lanes(buses):
    """(bus, edge, first beat bit) of every 16-bit lane of a beat of ``buses // 2`` words: word
    ``i`` of the beat (bits ``64 * i`` up) travels on buses A/B (i = 0) or C/D (i = 1)."""
    pairs = ("AB", "CD")[:buses // 2]
    return tuple((pair["AB".index(bus)], edge, 64 * i + first_bit)
                 for i, pair in enumerate(pairs) for bus, edge, first_bit in LANES)


def cycle_lanes(buses, beats):
    """(bus, edge index, first bit) of every 16-bit lane of a ``dmd`` cycle of ``beats`` beats:
    beat ``b`` (bits ``b * 32 * buses`` up of the cycle's words) travels on edges ``2b``
    (rising) and ``2b + 1`` (falling) of :func:`gateware.dlpc410.interface.din_layout`."""
    width = 32 * buses
    return tuple((bus, 2 * b + (0 if edge == "rise" else 1), b * width + first_bit)
                 for b in range(beats) for bus, edge, first_bit in beat_lanes(buses))


def word_to_lanes(word):
    """Split a 64-bit word (int) into ``{(bus, edge): 16-bit value}``."""
    return {(bus, edge): (word >> first_bit) & 0xffff for bus, edge, first_bit in LANES}


def lanes_to_word(lanes):
    """Inverse of :func:`word_to_lanes`."""
    word = 0
    for bus, edge, first_bit in LANES:
        word |= (lanes[(bus, edge)] & 0xffff) << first_bit
    return word
