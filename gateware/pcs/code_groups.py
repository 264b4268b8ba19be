"""8b/10b code-groups in fabric (IEEE 802.3 clause 36.2.4).

A byte ``HGFEDCBA`` is sent as ten bits ``abcdei fghj``: the 5b/6b sub-block codes ``EDCBA``
(Table 36-1a), the 3b/4b sub-block codes ``HGF`` (Table 36-1b, with the alternate ``A7`` for
D.x.7 where the primary would make a run of five), each chosen by the running disparity before
it. Twelve control code-groups exist (Table 36-2): K28.0 to K28.7, K23.7, K27.7, K29.7, K30.7.
K28.1, K28.5 and K28.7 begin with the comma ``0011111`` or ``1100000`` (clause 36.2.4.9).

Here a code-group is a 10-bit value with ``a``, the first bit on the line, in bit 0.

Running disparity (clause 36.2.4.4) is negative or positive; it starts negative. At the end of a
sub-block it is positive when the sub-block has more ones than zeros, or is ``000111`` or
``0011``; negative when it has more zeros, or is ``111000`` or ``1100``; else it is what it was
before the sub-block. A received code-group is invalid (clause 36.2.4.6) when it is in neither
column of the tables, or in the column of the other running disparity.

The tables below are the standard's columns for a negative running disparity; the positive
column is derived from them. :class:`Encoder` and :class:`Decoder` read whole-code-group tables
built from them at elaboration time.
"""

from amaranth import Cat, Module, Mux
from amaranth.lib import data, wiring
from amaranth.lib.memory import Memory
from amaranth.lib.wiring import In, Out

__all__ = ["CodeGroup", "Encoder", "Decoder", "CONTROLS", "K28_5", "encode", "decode_table"]

#: 5b/6b: ``abcdei`` of D.0 to D.31 for a negative running disparity (Table 36-1a).
SIX = [
    "100111", "011101", "101101", "110001", "110101", "101001", "011001", "111000",
    "111001", "100101", "010101", "110100", "001101", "101100", "011100", "010111",
    "011011", "100011", "010011", "110010", "001011", "101010", "011010", "111010",
    "110011", "100110", "010110", "110110", "001110", "101110", "011110", "101011",
]
#: 5b/6b of K.28 for a negative running disparity (Table 36-2); the other K codes use D.x's.
SIX_K28 = "001111"
#: 3b/4b: ``fghj`` of D.x.0 to D.x.P7 for a negative running disparity (Table 36-1b).
FOUR = ["1011", "1001", "0101", "1100", "1101", "1010", "0110", "1110"]
#: The alternate D.x.A7.
FOUR_A7 = "0111"
#: D.x.A7 replaces D.x.P7 after these x for a negative, and a positive, running disparity.
A7_AFTER = ({17, 18, 20}, {11, 13, 14})
#: 3b/4b of K.x.0 to K.x.7 for a negative running disparity (Table 36-2); the positive column
#: is their complement, balanced or not.
FOUR_K = ["1011", "0110", "1010", "1100", "1101", "0101", "1001", "0111"]
#: The twelve control code-groups as bytes (Table 36-2).
CONTROLS = [0x1C | y << 5 for y in range(8)] + [0xF7, 0xFB, 0xFD, 0xFE]
#: K28.5, the comma of /I/ and /C/; K30.7 (/V/), what a control byte not in the table becomes.
K28_5 = 0xBC
K30_7 = 0xFE
#: Control bytes whose code-group starts with a comma: K28.1, K28.5, K28.7.
COMMAS = {0x3C, 0xBC, 0xFC}


def _invert(bits):
    return "".join("1" if b == "0" else "0" for b in bits)


def _positive_column(bits):
    """The entry of the positive column: the complement, but for balanced sub-blocks that are
    not ``111000`` or ``1100``, which serve both."""
    balanced = 2 * bits.count("1") == len(bits)
    return bits if balanced and bits not in ("111000", "1100") else _invert(bits)


def disparity_after(bits, disparity):
    """Running disparity (0 negative, 1 positive) at the end of sub-block ``bits``."""
    ones, half = bits.count("1"), len(bits) // 2
    if ones > half or bits in ("000111", "0011"):
        return 1
    if ones < half or bits in ("111000", "1100"):
        return 0
    return disparity


def encode(byte, control, disparity):
    """Code-group (``a`` in bit 0) and running disparity after it, for ``byte`` sent as data or
    control from running disparity ``disparity``; a control byte not among :data:`CONTROLS`
    is sent as K30.7."""
    if control and byte not in CONTROLS:
        byte = K30_7
    x, y = byte & 0x1F, byte >> 5
    six = SIX_K28 if control and x == 28 else SIX[x]
    six = six if disparity == 0 else _positive_column(six)
    middle = disparity_after(six, disparity)
    if control:
        four = FOUR_K[y] if middle == 0 else _invert(FOUR_K[y])
    else:
        four = FOUR_A7 if y == 7 and x in A7_AFTER[middle] else FOUR[y]
        four = four if middle == 0 else _positive_column(four)
    bits = six + four
    return int(bits[::-1], 2), disparity_after(four, middle)


class _Entry(data.Struct):
    """What the decoder's table holds for one 10-bit value."""
    data: 8
    control: 1
    comma: 1
    # in the negative, and the positive, running disparity's column
    negative: 1
    positive: 1
    # whether the code-group sets the running disparity, and to what
    sets: 1
    sign: 1


def decode_table():
    """``{code: (byte, control, columns)}`` over every code-group of the tables, ``columns``
    the set of running disparities (0, 1) whose column holds it."""
    table = {}
    for control in (0, 1):
        for byte in (CONTROLS if control else range(256)):
            for disparity in (0, 1):
                code, _ = encode(byte, control, disparity)
                _, _, columns = table.setdefault(code, (byte, control, set()))
                assert table[code][:2] == (byte, control), f"{code:010b} decodes two ways"
                columns.add(disparity)
    return table


def _bits(code):
    return "".join(str(code >> i & 1) for i in range(10))


def _decoder_entries():
    table = decode_table()
    for code in range(1024):
        bits = _bits(code)
        after = disparity_after(bits[6:], disparity_after(bits[:6], None))
        byte, control, columns = table.get(code, (0, 0, set()))
        yield {
            "data": byte, "control": control, "comma": int(control and byte in COMMAS),
            "negative": int(0 in columns), "positive": int(1 in columns),
            "sets": int(after is not None), "sign": after or 0,
        }


class CodeGroup(data.Struct):
    """A received code-group, decoded: the byte, whether it is a control code-group (``comma``:
    K28.1, K28.5 or K28.7), and why it is invalid if it is: ``code_error`` when it is in no
    column of the tables (the byte is then 0), ``disparity_error`` when it is only in the other
    running disparity's column (the byte is then the one it stands for)."""
    data: 8
    control: 1
    comma: 1
    code_error: 1
    disparity_error: 1

    def invalid(self):
        return self.code_error | self.disparity_error


class Encoder(wiring.Component):
    """8b/10b encoder: a byte in a cycle, its code-group out the next.

    Members
    -------
    data : In(8)
    control : In(1)
        Send ``data`` as a control code-group (:data:`CONTROLS`; any other byte goes as K30.7).
    code : Out(10)
        The code-group of the byte of the cycle before, registered; ``a`` in bit 0.
    disparity : Out(1)
        The running disparity after ``code`` (1 positive); it starts negative. The transmitter
        reads it to choose the idle that brings it back to negative.
    """

    data: In(8)
    control: In(1)
    code: Out(10)
    disparity: Out(1)

    def elaborate(self, platform):
        m = Module()
        init = []
        for index in range(1024):
            byte, control, disparity = index & 0xFF, index >> 8 & 1, index >> 9
            code, after = encode(byte, control, disparity)
            init.append(code | after << 10)
        m.submodules.table = table = Memory(shape=11, depth=1024, init=init)
        read = table.read_port(domain="comb")
        m.d.comb += read.addr.eq(Cat(self.data, self.control, self.disparity))
        m.d.sync += [self.code.eq(read.data[:10]), self.disparity.eq(read.data[10])]
        return m


class Decoder(wiring.Component):
    """8b/10b decoder: a code-group in a cycle, the byte and its validity out the next.

    Members
    -------
    code : In(10)
        An aligned code-group, ``a`` in bit 0, one every cycle.
    group : Out(:class:`CodeGroup`)
        ``code`` of the cycle before, decoded against the running disparity before it.
    disparity : Out(1)
        The running disparity after ``group``'s code-group (1 positive), worked out from the
        bits received, so that one bad code-group does not make the ones after it bad too.
    """

    code: In(10)
    group: Out(CodeGroup)
    disparity: Out(1)

    def elaborate(self, platform):
        m = Module()
        m.submodules.table = table = Memory(shape=_Entry, depth=1024, init=list(_decoder_entries()))
        read = table.read_port(domain="comb")
        entry = read.data
        m.d.comb += read.addr.eq(self.code)
        in_table = entry.negative | entry.positive
        in_column = Mux(self.disparity, entry.positive, entry.negative)
        m.d.sync += [
            self.group.data.eq(entry.data),
            self.group.control.eq(entry.control),
            self.group.comma.eq(entry.comma),
            self.group.code_error.eq(~in_table),
            self.group.disparity_error.eq(in_table & ~in_column),
            self.disparity.eq(Mux(entry.sets, entry.sign, self.disparity)),
        ]
        return m
