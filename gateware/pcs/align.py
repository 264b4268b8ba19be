"""Code-group alignment on the comma (IEEE 802.3 clause 36.3.2.4 and 36.2.4.9).

The transceiver hands over ten line bits a cycle, first bit in bit 0, with no idea where a
code-group starts. The comma, ``0011111`` or ``1100000`` (bits ``abcdeif`` of K28.1, K28.5 and
K28.7), appears in a valid stream only at the start of a code-group, so finding one says where
code-groups start. The aligner looks at the last two words (a 20-bit window: every start
position 0..9 of the older word with its ten bits and its comma inside) and, on a comma, moves
its boundary there.
"""

from amaranth import Cat, Module, Signal
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

__all__ = ["Aligner", "COMMA", "COMMA_WIDTH"]

#: The comma's bits ``abcdeif`` with ``a`` in bit 0 (``0011111``), and its width; its
#: complement ``1100000`` is the other comma.
COMMA = 0b1111100
COMMA_WIDTH = 7


class Aligner(wiring.Component):
    """Finds the comma in the line bits and gives whole code-groups.

    Members
    -------
    bits : In(10)
        Line bits from the transceiver, first in bit 0, one word a cycle.
    enable : In(1, init=1)
        Move the boundary on commas; low holds it where it is.
    code : Out(10)
        A code-group, registered, two cycles after its last bit came in ``bits``.
    comma : Out(1)
        ``code`` begins with a comma.
    offset : Out(range(10))
        The boundary: where, in a word of ``bits``, a code-group begins.
    slips : Out(counter_width)
        Times the boundary moved (wraps): a link that keeps slipping has a bad clock or cable.
    """

    def __init__(self, *, counter_width=16):
        super().__init__({
            "bits": In(10),
            "enable": In(1, init=1),
            "code": Out(10),
            "comma": Out(1),
            "offset": Out(range(10)),
            "slips": Out(counter_width),
        })

    def elaborate(self, platform):
        m = Module()
        older = Signal(10)
        m.d.sync += older.eq(self.bits)
        window = Cat(older, self.bits)

        # A comma at each start position of the older word; the lowest wins.
        found = Signal(10)
        for start in range(10):
            bits = window[start:start + COMMA_WIDTH]
            m.d.comb += found[start].eq((bits == COMMA) | (bits == (~COMMA & 0x7F)))
        start = Signal(range(10))
        for position in reversed(range(10)):
            with m.If(found[position]):
                m.d.comb += start.eq(position)

        offset = Signal(range(10))
        m.d.comb += offset.eq(self.offset)
        with m.If(self.enable & found.any()):
            m.d.comb += offset.eq(start)
            with m.If(start != self.offset):
                m.d.sync += self.slips.eq(self.slips + 1)
        m.d.sync += [
            self.offset.eq(offset),
            self.code.eq(window.bit_select(offset, 10)),
            self.comma.eq((found >> offset)[0]),
        ]
        return m
