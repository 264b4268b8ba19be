"""The DDR2 writer: plane words in, MCB write bursts out (``sync`` domain).

The serialiser emits the eight planes of every 64-pixel run in turn, but DDR2 keeps planes apart
(:mod:`gateware.store.addresses`). The writer therefore gathers rows in a buffer and then writes
them plane by plane. Consecutive rows of one plane are contiguous in memory, so rows that arrive
in order (row r, then r+1, of the same slot) share a bank and go out as one burst per plane, up
to ``max_burst`` words (32: two DLP7000 rows, one DLP9500 row); a row that does not follow on,
a frame's completing row, or a full bank closes the bank. The buffer has two banks: one fills
while the other drains, so words are taken one per cycle as long as the memory keeps up;
otherwise ``words.ready`` falls and the pressure goes back to the network side. A bank holding
rows of a frame that never completes may wait for the next row to be closed; such a frame is
never shown.

Rules of the MCB port it keeps: nothing before ``calib_done``; a burst's words are all pushed
into the write FIFO (only when it has room for all of them) before its command is given; no
command while ``cmd_full``.

When the row that completes a frame has been written (its commands taken and the write FIFO
empty), the writer says so on ``written``: only then may the frame be read through another port.

While ``discard`` is high (the memory lost its calibration: :mod:`gateware.store.recovery`) the
writer is held in reset: it gives the port nothing, both banks are empty, and every word it is
given is dropped (all belong to rows begun before the loss, whose frames are forgotten).
"""

from amaranth import Module, Mux, ResetInserter, Signal
from amaranth.lib import data, stream, wiring
from amaranth.lib.memory import Memory
from amaranth.lib.wiring import In, Out
from amaranth.utils import ceil_log2

from . import mcb
from .addresses import PLANES, AddressMap
from .layouts import SLOT_BITS

__all__ = ["Writer", "WriteDrain", "bank_layout", "write_word_layout"]


def write_word_layout(dmd):
    """One word to store: its data, slot and place; ``last`` on the final word of a row (the
    writer then writes the row), ``completes`` with ``last`` when that row completes its frame."""
    return data.StructLayout({
        "data": 64,
        "slot": SLOT_BITS,
        "plane": 3,
        "row": ceil_log2(dmd.rows),
        "word": max(1, ceil_log2(dmd.words_per_row)),
        "last": 1,
        "completes": 1,
    })


def bank_layout(dmd, max_burst):
    """What a bank of the writer's buffer holds, for its drain: whether it is closed (``full``),
    the planes its rows have, their slot, first row and count, and whether the last of them
    completes its frame."""
    return data.StructLayout({
        "full": 1,
        "planes": PLANES,
        "slot": SLOT_BITS,
        "first_row": ceil_log2(dmd.rows),
        "rows": range(max_burst // dmd.words_per_row + 1),
        "completes": 1,
    })


class Writer(wiring.Component):
    """Write rows of plane words to DDR2 through an MCB port.

    Parameters
    ----------
    dmd : :class:`spec.facts.DmdType`
        Geometry (words per row, rows).
    slots : int
        Frame slots in the memory (the address map).
    max_burst : int
        Longest burst in words. Rows that follow each other in one slot go out together, as
        many whole rows as fit in this many words per plane: 32 (two XGA rows, one 1080p row,
        one WXGA row of 20 words), half the write FIFO, so that one burst fills the FIFO while
        the previous one drains.
    settle : int
        Cycles to wait after a command before trusting ``wr_count``, ``cmd_empty`` and
        ``wr_empty`` again (the MCB updates them a little late).

    Members
    -------
    words : In(stream.Signature(write_word_layout(dmd)))
        The words of whole rows, in any order within the row; the planes present in a row are
        the planes written for it.
    written : Out(stream.Signature(SLOT_BITS))
        The slot whose completing row (``completes``) is now in memory.
    discard : In(1)
        Drop everything held and given; no MCB traffic.
    mcb : Out(mcb.PortSignature(64))
        MCB port 0, clocked by ``sync``; only the write half is used.
    """

    def __init__(self, dmd, *, slots=16, max_burst=32, settle=2):
        assert dmd.words_per_row <= max_burst <= mcb.MAX_BURST
        self._dmd = dmd
        self._map = AddressMap(dmd, slots)
        self._max_burst = max_burst
        self._settle = settle
        super().__init__({
            "words": In(stream.Signature(write_word_layout(dmd))),
            "written": Out(stream.Signature(SLOT_BITS)),
            "discard": In(1),
            "mcb": Out(mcb.PortSignature(64)),
        })

    def elaborate(self, platform):
        m = Module()
        dmd, max_burst = self._dmd, self._max_burst
        row_words = dmd.words_per_row
        group = max_burst // row_words           # rows per bank
        bank_words = PLANES * max_burst

        m.submodules.buffer = buffer = Memory(shape=64, depth=2 * bank_words, init=[])
        fill_port = buffer.write_port()
        drain_port = buffer.read_port()

        # Per bank: a run of consecutive rows of one slot, which planes they have, whether the
        # last of them completes its frame, and whether the bank is closed (ready to drain).
        full = [Signal(name=f"full{bank}") for bank in range(2)]
        planes = [Signal(PLANES, name=f"planes{bank}") for bank in range(2)]
        slot = [Signal(SLOT_BITS, name=f"slot{bank}") for bank in range(2)]
        first_row = [Signal.like(self.words.payload.row, name=f"first_row{bank}") for bank in range(2)]
        rows = [Signal(range(group + 1), name=f"rows{bank}") for bank in range(2)]
        completes = [Signal(name=f"completes{bank}") for bank in range(2)]
        # the row that would join the bank next, ``first_row + rows`` (kept with them, so that
        # whether a word joins the bank is a compare, with no sum before it)
        expect = [Signal(len(self.words.payload.row) + 1, name=f"expect{bank}") for bank in range(2)]

        def of_bank(index, signals, name):
            value = Signal.like(signals[0], name=name)
            m.d.comb += value.eq(signals[0])
            with m.If(index):
                m.d.comb += value.eq(signals[1])
            return value

        # -- fill: one word per cycle into the open bank
        fill_bank = Signal()
        in_row = Signal()                        # a row has started and not ended
        word = self.words.payload
        fill_full = of_bank(fill_bank, full, "fill_full")
        fill_rows = of_bank(fill_bank, rows, "fill_rows")
        fill_slot = of_bank(fill_bank, slot, "fill_slot")
        fill_expect = of_bank(fill_bank, expect, "fill_expect")
        continues = Signal()
        m.d.comb += continues.eq((fill_rows == 0) | ((word.slot == fill_slot) & (word.row == fill_expect)))
        breaks = Signal()                        # this word starts a row that cannot join the bank
        m.d.comb += breaks.eq(~in_row & ~continues)
        take = Signal()
        discard = self.discard
        m.d.comb += [
            self.words.ready.eq((~fill_full & ~breaks) | discard),
            take.eq(self.words.valid & self.words.ready & ~discard),
            fill_port.addr.eq(fill_bank * bank_words + word.plane * max_burst + fill_rows * row_words + word.word),
            fill_port.data.eq(word.data),
            fill_port.en.eq(take),
        ]
        closes = Signal()
        with m.If(self.words.valid & ~fill_full & breaks):
            m.d.comb += closes.eq(1)
        with m.If(take):
            m.d.sync += in_row.eq(~word.last)
            with m.If(word.last & (word.completes | (fill_rows == group - 1))):
                m.d.comb += closes.eq(1)
        for bank in range(2):
            with m.If(fill_bank == bank):
                with m.If(take):
                    m.d.sync += planes[bank].eq(planes[bank] | (1 << word.plane))
                    opens = ~in_row & (rows[bank] == 0)
                    with m.If(opens):
                        m.d.sync += [slot[bank].eq(word.slot), first_row[bank].eq(word.row),
                                     expect[bank].eq(word.row)]
                    with m.If(word.last):
                        m.d.sync += [rows[bank].eq(rows[bank] + 1), completes[bank].eq(word.completes),
                                     expect[bank].eq(Mux(opens, word.row, expect[bank]) + 1)]
                with m.If(closes):
                    m.d.sync += full[bank].eq(1)
        with m.If(closes):
            m.d.sync += fill_bank.eq(~fill_bank)

        # -- drain (:class:`WriteDrain`): the closed bank to the memory, then emptied (after the
        # fill's changes above, so that emptying a bank wins over them)
        m.submodules.drain = drain = WriteDrain(dmd, self._map, max_burst=max_burst, settle=self._settle)
        held = {"full": full, "planes": planes, "slot": slot, "first_row": first_row, "rows": rows,
                "completes": completes}
        for name, signals in held.items():
            m.d.comb += drain.held[name].eq(of_bank(drain.bank, signals, f"drain_{name}"))
        m.d.comb += [drain_port.addr.eq(drain.read_address), drain.data.eq(drain_port.data), drain.discard.eq(discard)]
        wiring.connect(m, drain.mcb, wiring.flipped(self.mcb))
        wiring.connect(m, drain.written, wiring.flipped(self.written))
        for bank in range(2):
            with m.If(drain.release & (drain.bank == bank)):
                m.d.sync += [full[bank].eq(0), planes[bank].eq(0), rows[bank].eq(0), completes[bank].eq(0)]
        # the memory is lost: everything held is forgotten (the drain keeps the port quiet in the
        # cycle discard rises)
        return ResetInserter(discard)(m)


class WriteDrain(wiring.Component):
    """The writer's closed bank to DDR2, plane by plane: a plane's words into the MCB's write FIFO,
    then its command (``sync``).

    A plane the bank's rows do not have is skipped. The words of a burst go in only when the
    write FIFO has room for all of them, and the command after the last (never while
    ``cmd_full``); ``settle`` cycles after a command pass before ``wr_count``, ``cmd_empty`` and
    ``wr_empty`` are trusted again. A bank whose last row completes its frame is released once its
    commands are taken and the write FIFO is empty, and its slot told on ``written``; any other
    bank as soon as its last command is given.

    Parameters
    ----------
    dmd : :class:`spec.facts.DmdType`
        Geometry (words per row, rows).
    address_map : :class:`~gateware.store.addresses.AddressMap`
        Where the rows go.
    max_burst : int
        Words of a plane in a bank.
    settle : int
        Cycles to wait after a command before trusting the port's counts.

    Members
    -------
    bank : Out(1)
        The bank drained; the other one once this one is released.
    held : In(bank_layout(dmd, max_burst))
        What that bank holds.
    release : Out(1)
        That bank is written: empty it (the other one is drained from the next cycle on).
    read_address : Out(range(2 * PLANES * max_burst))
        The buffer's word to push next, read for the next cycle.
    data : In(64)
        The buffer's word at the last cycle's ``read_address``.
    discard : In(1)
        The writer is held in reset: no MCB traffic.
    mcb : Out(mcb.PortSignature(64))
        MCB port 0; only the write half is used.
    written : Out(stream.Signature(SLOT_BITS))
        The slot whose completing row is now in memory.
    """

    def __init__(self, dmd, address_map, *, max_burst, settle):
        self._row_words, self._map = dmd.words_per_row, address_map
        self._max_burst, self._settle = max_burst, settle
        super().__init__({
            "bank": Out(1),
            "held": In(bank_layout(dmd, max_burst)),
            "release": Out(1),
            "read_address": Out(range(2 * PLANES * max_burst)),
            "data": In(64),
            "discard": In(1),
            "mcb": Out(mcb.PortSignature(64)),
            "written": Out(stream.Signature(SLOT_BITS)),
        })

    def elaborate(self, platform):
        m = Module()
        max_burst, port, held, discard = self._max_burst, self.mcb, self.held, self.discard
        plane = Signal(range(PLANES))
        index = Signal(range(max_burst + 1))
        pushing = Signal()          # the buffer word read last cycle goes into the write FIFO now
        settle = Signal(range(self._settle + 1))
        words = Signal(range(max_burst + 1))
        m.d.comb += [
            words.eq(held.rows * self._row_words),
            self.read_address.eq(self.bank * (PLANES * max_burst) + plane * max_burst + index),
            port.wr_en.eq(pushing & ~discard),
            port.wr_data.eq(self.data),
            port.wr_mask.eq(0),
            port.cmd_instr.eq(mcb.Instr.WRITE),
            port.cmd_bl.eq(words - 1),
            port.cmd_byte_addr.eq(self._map.address(held.slot, plane, held.first_row)),
            self.written.payload.eq(held.slot),
        ]
        m.d.sync += pushing.eq(0)
        with m.If(settle != 0):
            m.d.sync += settle.eq(settle - 1)
        with m.If(self.release):
            m.d.sync += self.bank.eq(~self.bank)

        with m.FSM():
            with m.State("IDLE"):
                with m.If(held.full):
                    m.d.sync += plane.eq(0)
                    m.next = "PLANE"
            with m.State("PLANE"):
                with m.If(~held.planes.bit_select(plane, 1)):
                    m.d.sync += plane.eq(plane + 1)
                    with m.If(plane == PLANES - 1):
                        m.next = "DONE"
                with m.Elif(port.calib_done & (settle == 0) & (port.wr_count + words <= mcb.FIFO_DEPTH)):
                    m.d.sync += index.eq(0)
                    m.next = "PUSH"
            with m.State("PUSH"):
                m.d.sync += [pushing.eq(1), index.eq(index + 1)]
                with m.If(index == words - 1):
                    m.next = "COMMAND"
            with m.State("COMMAND"):
                # the last word was pushed in this cycle's edge at the latest; give the command after
                with m.If(~pushing & ~port.cmd_full & ~discard):
                    m.d.comb += port.cmd_en.eq(1)
                    m.d.sync += [plane.eq(plane + 1), settle.eq(self._settle)]
                    with m.If(plane == PLANES - 1):
                        m.next = "DONE"
                    with m.Else():
                        m.next = "PLANE"
            with m.State("DONE"):
                with m.If(~held.completes):
                    m.d.comb += self.release.eq(1)
                    m.next = "IDLE"
                with m.Elif((settle == 0) & port.cmd_empty & port.wr_empty):
                    m.next = "WRITTEN"
            with m.State("WRITTEN"):
                m.d.comb += self.written.valid.eq(~discard)
                with m.If(self.written.ready & ~discard):
                    m.d.comb += self.release.eq(1)
                    m.next = "IDLE"
        return m
