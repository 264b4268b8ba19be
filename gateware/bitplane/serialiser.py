"""The bit-plane serialiser: 8-bit pixels in, 64-bit single-plane words out.

Grey levels are shown by binary-weighted PWM, so the DMD wants an image as eight bit-planes.
This block slices pixels as they arrive and packs each plane's bits into 64-bit words, the unit
of the DDR2 store and one DLPC410 beat, so that on a trigger a plane streams out unchanged.

Order of the output
-------------------
For every 64 pixels of a row (one *word position* ``w``), eight words leave, plane 0 (the least
significant bit of the pixels) first and plane 7 last; each carries its plane, row, word
position, DMD block and frame. Word bit ``i`` is pixel column ``64 * w + i``; how the bits then
travel on DIN_A/DIN_B is :mod:`gateware.dlpc410.beat`'s business.

After the last word of a row, a ``rows`` transfer says, per plane, whether any bit of that row
is set; the store ORs these over the rows of each block into its occupancy map (records may
arrive in any order, so the OR over a block belongs where the frame is kept).
"""

from amaranth import Array, Cat, Module, Mux, Signal
from amaranth.lib import data, stream, wiring
from amaranth.lib.wiring import In, Out
from amaranth.utils import ceil_log2

from ..protocol.layouts import copy_tag, pixel_layout, position_fields

__all__ = ["Serialiser", "word_layout", "row_flags_layout", "PLANES"]

PLANES = 8
WORD_BITS = 64


def word_layout(dmd, frame_bits=4):
    """One 64-bit word of one bit-plane, with its place in the frame."""
    return data.StructLayout({
        "data": WORD_BITS,
        "plane": ceil_log2(PLANES),
        "word": max(1, ceil_log2(dmd.words_per_row)),
        "block": max(1, ceil_log2(dmd.blocks)),
        **position_fields(dmd, frame_bits),
    })


def row_flags_layout(dmd, frame_bits=4):
    """Per-plane any-bit-set flags of one complete row."""
    return data.StructLayout({
        "planes": PLANES,
        "block": max(1, ceil_log2(dmd.blocks)),
        **position_fields(dmd, frame_bits),
    })


class Serialiser(wiring.Component):
    """Slice 8-bit pixels into 64-bit bit-plane words.

    Parameters
    ----------
    dmd : :class:`spec.facts.DmdType`
        Geometry: columns per row, rows per block.
    lanes : int
        Pixels per input transfer (1, 2, 4 or 8). With 8 lanes the block takes 8 pixels and
        emits one word every cycle.
    frame_bits : int
        Width of the frame tag carried from input to output.

    Members
    -------
    pixels : In(stream.Signature(:func:`gateware.protocol.layouts.pixel_layout`))
        Pixels of whole rows, left to right (``column`` is that of the first pixel of the
        transfer and a multiple of ``lanes``). Rows may come in any order.
    words : Out(stream.Signature(word_layout))
        Eight words per 64-pixel run, plane 0 first.
    rows : Out(stream.Signature(row_flags_layout))
        One transfer per completed row: per plane, whether any bit in the row is set.
    """

    def __init__(self, dmd, *, lanes=1, frame_bits=4):
        assert lanes in (1, 2, 4, 8)
        self._dmd = dmd
        self._lanes = lanes
        super().__init__({
            "pixels": In(stream.Signature(pixel_layout(dmd, lanes, frame_bits))),
            "words": Out(stream.Signature(word_layout(dmd, frame_bits))),
            "rows": Out(stream.Signature(row_flags_layout(dmd, frame_bits))),
        })

    def elaborate(self, platform):
        m = Module()
        dmd, lanes = self._dmd, self._lanes
        groups = WORD_BITS // lanes

        beat = self.pixels.payload
        group = beat.column[:ceil_log2(WORD_BITS)] >> ceil_log2(lanes) if lanes > 1 \
            else beat.column[:ceil_log2(WORD_BITS)]
        word_pos = beat.column >> ceil_log2(WORD_BITS)
        last_group = group == groups - 1

        # Bits of plane k of this transfer, leftmost pixel in the lowest bit.
        def slice_bits(k):
            return Cat(beat.pixels[j][k] for j in range(lanes))

        # Planes being assembled: one 64-bit register per plane.
        assembling = Array(Signal(WORD_BITS, name=f"assembling{k}") for k in range(PLANES))
        # The complete run's eight words, drained one per transfer while the next run assembles.
        held = Array(Signal(WORD_BITS, name=f"held{k}") for k in range(PLANES))
        held_valid = Signal()
        plane = Signal(range(PLANES))
        held_tag = Signal.like(self.words.payload)

        # Row flags: ORed over the word positions of the row being completed.
        row_any = Signal(PLANES)
        flags_valid = Signal()
        flags = Signal.like(self.rows.payload)

        drained = self.words.valid & self.words.ready & (plane == PLANES - 1)
        held_free = ~held_valid | drained
        last_word_of_row = word_pos == dmd.words_per_row - 1
        flags_free = ~flags_valid | self.rows.ready

        m.d.comb += self.pixels.ready.eq(~last_group | (held_free & (flags_free | ~last_word_of_row)))

        # Block number from the row: a comparator chain, since rows per block need not be a power of 2.
        block = Signal.like(self.words.payload.block)
        for b in range(1, dmd.blocks):
            with m.If(beat.row >= b * dmd.rows_per_block):
                m.d.comb += block.eq(b)

        completed = [Cat(assembling[k][:WORD_BITS - lanes], slice_bits(k)) for k in range(PLANES)]
        with m.If(self.pixels.valid & self.pixels.ready):
            with m.If(~last_group):
                for k in range(PLANES):
                    m.d.sync += assembling[k].word_select(group, lanes).eq(slice_bits(k))
            with m.Else():
                for k in range(PLANES):
                    m.d.sync += held[k].eq(completed[k])
                m.d.sync += [
                    held_valid.eq(1),
                    plane.eq(0),
                    *copy_tag(held_tag, beat),
                    held_tag.row.eq(beat.row),
                    held_tag.word.eq(word_pos),
                    held_tag.block.eq(block),
                ]
                any_now = Cat(completed[k].any() for k in range(PLANES))
                row_so_far = Signal(PLANES)
                m.d.comb += row_so_far.eq(Mux(word_pos == 0, any_now, any_now | row_any))
                m.d.sync += row_any.eq(row_so_far)
                with m.If(last_word_of_row):
                    m.d.sync += [
                        flags_valid.eq(1),
                        flags.planes.eq(row_so_far),
                        *copy_tag(flags, beat),
                        flags.row.eq(beat.row),
                        flags.block.eq(block),
                    ]

        with m.If(self.words.valid & self.words.ready):
            m.d.sync += plane.eq(plane + 1)
            with m.If((plane == PLANES - 1) & ~(self.pixels.valid & self.pixels.ready & last_group)):
                m.d.sync += held_valid.eq(0)

        with m.If(self.rows.valid & self.rows.ready
                  & ~(self.pixels.valid & self.pixels.ready & last_group & last_word_of_row)):
            m.d.sync += flags_valid.eq(0)

        m.d.comb += [
            self.words.valid.eq(held_valid),
            *copy_tag(self.words.payload, held_tag),
            self.words.payload.row.eq(held_tag.row),
            self.words.payload.word.eq(held_tag.word),
            self.words.payload.block.eq(held_tag.block),
            self.words.payload.data.eq(held[plane]),
            self.words.payload.plane.eq(plane),
            self.rows.valid.eq(flags_valid),
            self.rows.payload.eq(flags),
        ]
        return m

