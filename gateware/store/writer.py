"""The DDR2 writer (DESIGN.md block 5): plane words in, MCB write bursts out (``sync`` domain).

The serialiser emits the eight planes of every 64-pixel run in turn, but DDR2 keeps planes apart
(:mod:`gateware.store.addresses`). The writer therefore gathers one whole row in a row buffer
and then writes it plane by plane: one burst of ``words_per_row`` words per plane (16 for the
DLP7000, 32 for the DLP9500), the longest contiguous run a row gives, since rows may arrive in
any order. The buffer has two banks: one fills while the other drains, so words are taken one
per cycle as long as the memory keeps up; otherwise ``words.ready`` falls and the pressure goes
back to the network side.

Rules of the MCB port it keeps: nothing before ``calib_done``; a burst's words are all pushed
into the write FIFO (only when it has room for all of them) before its command is given; no
command while ``cmd_full``.

When the row that completes a frame has been written (its commands taken and the write FIFO
empty), the writer says so on ``written``: only then may the frame be read through another port.
"""

from amaranth import Module, Signal
from amaranth.lib import data, stream, wiring
from amaranth.lib.memory import Memory
from amaranth.lib.wiring import In, Out
from amaranth.utils import ceil_log2

from . import mcb
from .addresses import PLANES, AddressMap
from .layouts import SLOT_BITS

__all__ = ["Writer", "write_word_layout"]


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


class Writer(wiring.Component):
    """Write rows of plane words to DDR2 through an MCB port.

    Parameters
    ----------
    dmd : :class:`gateware.dlpc410.facts.DmdType`
        Geometry (words per row, rows).
    slots : int
        Frame slots in the memory (the address map).
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
    mcb : Out(mcb.PortSignature())
        MCB port 0, clocked by ``sync``; only the write half is used.
    """

    def __init__(self, dmd, *, slots=16, settle=2):
        self._dmd = dmd
        self._map = AddressMap(dmd, slots)
        self._settle = settle
        super().__init__({
            "words": In(stream.Signature(write_word_layout(dmd))),
            "written": Out(stream.Signature(SLOT_BITS)),
            "mcb": Out(mcb.PortSignature()),
        })

    def elaborate(self, platform):
        m = Module()
        dmd = self._dmd
        wpr = dmd.words_per_row
        bank_words = PLANES * wpr
        assert wpr <= mcb.MAX_BURST

        m.submodules.buffer = buffer = Memory(shape=64, depth=2 * bank_words, init=[])
        fill_port = buffer.write_port()
        drain_port = buffer.read_port()

        # Per bank: holds a complete row to drain, which planes it has, where it goes.
        full = [Signal(name=f"full{b}") for b in range(2)]
        planes = [Signal(PLANES, name=f"planes{b}") for b in range(2)]
        slot = [Signal(SLOT_BITS, name=f"slot{b}") for b in range(2)]
        row = [Signal.like(self.words.payload.row, name=f"row{b}") for b in range(2)]
        completes = [Signal(name=f"completes{b}") for b in range(2)]

        # -- fill: one word per cycle into the bank being filled
        fill_bank = Signal()
        word = self.words.payload
        fill_full = Signal()
        m.d.comb += fill_full.eq((full[0] & ~fill_bank) | (full[1] & fill_bank))
        m.d.comb += [
            self.words.ready.eq(~fill_full),
            fill_port.addr.eq((fill_bank * bank_words) + word.plane * wpr + word.word),
            fill_port.data.eq(word.data),
            fill_port.en.eq(self.words.valid & ~fill_full),
        ]
        for b in range(2):
            with m.If(self.words.valid & self.words.ready & (fill_bank == b)):
                m.d.sync += [planes[b].eq(planes[b] | (1 << word.plane)), slot[b].eq(word.slot),
                             row[b].eq(word.row)]
                with m.If(word.last):
                    m.d.sync += [full[b].eq(1), completes[b].eq(word.completes)]
        with m.If(self.words.valid & self.words.ready & word.last):
            m.d.sync += fill_bank.eq(~fill_bank)

        # -- drain: plane by plane, data first, then the command
        port = self.mcb
        drain_bank = Signal()
        plane = Signal(range(PLANES))
        index = Signal(range(wpr + 1))
        pushing = Signal()          # the buffer word read last cycle goes into the write FIFO now
        settle = Signal(range(self._settle + 1))
        d_planes = Signal(PLANES)
        d_slot = Signal(SLOT_BITS)
        d_row = Signal.like(row[0])
        d_completes = Signal()
        for b in range(2):
            with m.If(drain_bank == b):
                m.d.comb += [d_planes.eq(planes[b]), d_slot.eq(slot[b]), d_row.eq(row[b]),
                             d_completes.eq(completes[b])]

        m.d.comb += [
            drain_port.addr.eq(drain_bank * bank_words + plane * wpr + index),
            port.wr_en.eq(pushing),
            port.wr_data.eq(drain_port.data),
            port.wr_mask.eq(0),
            port.cmd_instr.eq(mcb.Instr.WRITE),
            port.cmd_bl.eq(wpr - 1),
            port.cmd_byte_addr.eq(self._map.address(d_slot, plane, d_row)),
            self.written.payload.eq(d_slot),
        ]
        m.d.sync += pushing.eq(0)
        with m.If(settle != 0):
            m.d.sync += settle.eq(settle - 1)

        def release_bank():
            for b in range(2):
                with m.If(drain_bank == b):
                    m.d.sync += [full[b].eq(0), planes[b].eq(0)]
            m.d.sync += drain_bank.eq(~drain_bank)

        with m.FSM():
            with m.State("IDLE"):
                with m.If((full[0] & ~drain_bank) | (full[1] & drain_bank)):
                    m.d.sync += plane.eq(0)
                    m.next = "PLANE"
            with m.State("PLANE"):
                with m.If(~d_planes.bit_select(plane, 1)):
                    m.d.sync += plane.eq(plane + 1)
                    with m.If(plane == PLANES - 1):
                        m.next = "DONE"
                with m.Elif(port.calib_done & (settle == 0) & (port.wr_count <= mcb.FIFO_DEPTH - wpr)):
                    m.d.sync += index.eq(0)
                    m.next = "PUSH"
            with m.State("PUSH"):
                m.d.sync += [pushing.eq(1), index.eq(index + 1)]
                with m.If(index == wpr - 1):
                    m.next = "COMMAND"
            with m.State("COMMAND"):
                # the last word was pushed in this cycle's edge at the latest; give the command after
                with m.If(~pushing & ~port.cmd_full):
                    m.d.comb += port.cmd_en.eq(1)
                    m.d.sync += [plane.eq(plane + 1), settle.eq(self._settle)]
                    with m.If(plane == PLANES - 1):
                        m.next = "DONE"
                    with m.Else():
                        m.next = "PLANE"
            with m.State("DONE"):
                with m.If(~d_completes):
                    release_bank()
                    m.next = "IDLE"
                with m.Elif((settle == 0) & port.cmd_empty & port.wr_empty):
                    m.next = "WRITTEN"
            with m.State("WRITTEN"):
                m.d.comb += self.written.valid.eq(1)
                with m.If(self.written.ready):
                    release_bank()
                    m.next = "IDLE"
        return m
