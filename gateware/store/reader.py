"""The plane reader: planes out of DDR2 for the sequencer (``dmd`` domain).

A :class:`~gateware.store.layouts.PlaneRequest` names a slot, a plane and a run of rows; the
rows of a plane are one contiguous run of memory (:mod:`gateware.store.addresses`), so the
reader cuts it into read commands of up to 64 port words and gives them through MCB port 1,
clocked by ``dmd``. A slot holding a delta frame shows some rows from its base's slot: the
reader looks each row up in the row map (``sources``, one row a cycle) and reads each run of
rows from one slot as one contiguous run; a whole frame's request is one run, found from its
first row's lookup. The port is 64 or 128 bits wide: a 128-bit port word is two plane words, the
first in its low bits, and the reader hands it on as it is, so that a sequencer taking two words
a transfer gets them as fast as the memory gives them. The words go through a FIFO to the
sequencer, in order, requests one after another.

Look-ahead: the reader keeps issuing commands, across request boundaries, as long as the words
it has asked for and not yet handed on fit in its FIFO (``fifo_depth`` plane words, several
commands outstanding), so the memory's latency is hidden and a port word per ``dmd`` cycle
leaves whenever the memory delivers that fast. Because those words always have room, the reader
takes every word from the MCB's read FIFO as soon as it is there: that FIFO never overflows.

A request that does not fit the frame (slot beyond the slots, no rows, rows past the last) is
dropped and counted; it produces no words.

A lost memory (``store_lost``, from :mod:`gateware.store.recovery`): the MCB has dropped the
commands and words in flight, so the reader forgets them too (nothing reserved, nothing taken
from the port) and answers every word still owed beyond those it holds, and every request taken
until the store has recovered, with zeros; the sequencer is never left waiting for words that
will not come.
"""

from amaranth import DomainRenamer, Module, Mux, Signal
from amaranth.lib import stream, wiring
from amaranth.lib.fifo import SyncFIFOBuffered
from amaranth.lib.wiring import In, Out

from . import mcb
from .addresses import WORD_BYTES, AddressMap
from .layouts import SLOT_BITS, PlaneRequest
from .slot_maps import RowLookupSignature

__all__ = ["Reader"]


class Reader(wiring.Component):
    """Read runs of plane rows from DDR2 into a FIFO.

    Parameters
    ----------
    dmd : :class:`spec.facts.DmdType`
    slots : int
        Frame slots in the memory (the address map).
    fifo_depth : int
        Plane words of look-ahead and buffering (a multiple of 64 port words; 256 = four
        commands of a 64-bit port, or two of a 128-bit port, in flight).
    domain : str
        Clock domain of the reader and of its MCB port.
    width : int
        The MCB port's width: 64 or 128 bits, one or two plane words a transfer.

    Members
    -------
    requests : In(stream.Signature(PlaneRequest))
        What to read.
    planes : Out(stream.Signature(width))
        The rows' words in order, ``words_per_row * 64 / width`` transfers per row, word 0 first
        (in the low bits of the first transfer).
    mcb : Out(mcb.PortSignature(width))
        MCB port 1; only the read half is used.
    bad_requests : Out(16)
        Requests dropped because they do not fit the frame.
    store_lost : In(1)
        The store has lost its contents and not recovered yet (answer with zeros).
    sources : Out(RowLookupSignature(dmd))
        The row map: which slot each row of a slot shows, and whether the slot holds a delta.
    """

    def __init__(self, dmd, *, slots=16, fifo_depth=256, domain="dmd", width=128):
        assert width in (64, 128)
        words = width // 64                      # plane words per port word
        assert dmd.words_per_row % words == 0, "rows must start on a port word"
        assert fifo_depth % (mcb.MAX_BURST * words) == 0
        self._dmd, self._slots, self._width = dmd, slots, width
        self._map = AddressMap(dmd, slots)
        self._fifo_depth, self._domain = fifo_depth, domain
        super().__init__({
            "requests": In(stream.Signature(PlaneRequest)),
            "planes": Out(stream.Signature(width)),
            "mcb": Out(mcb.PortSignature(width)),
            "bad_requests": Out(16),
            "store_lost": In(1),
            "sources": Out(RowLookupSignature(dmd)),
        })

    def elaborate(self, platform):
        m = Module()
        dmd, port = self._dmd, self.mcb
        words = self._width // 64
        depth = self._fifo_depth // words        # port words
        port_words_per_row = dmd.words_per_row // words

        # the memory is lost: the words owed are answered as zeros (until none is owed)
        lost = self.store_lost
        zero = Signal()

        m.submodules.fifo = fifo = SyncFIFOBuffered(width=self._width, depth=depth)
        owed = Signal(range(depth + dmd.rows * port_words_per_row + 1))     # port words taken, not handed on
        # the words read before the loss go first (a word offered stays offered), then zeros
        with m.If(zero & ~fifo.r_stream.valid):
            m.d.comb += [self.planes.valid.eq(owed != 0), self.planes.payload.eq(0)]
        with m.Else():
            wiring.connect(m, fifo.r_stream, wiring.flipped(self.planes))

        address = Signal(30)
        remaining = Signal(range(dmd.words_per_plane // words + 1))     # port words
        reserved = Signal(range(depth + 1))      # asked for and not yet handed on
        burst = Signal(range(mcb.MAX_BURST + 1))
        m.d.comb += burst.eq(Mux(remaining > mcb.MAX_BURST, mcb.MAX_BURST, remaining))

        request = self.requests.payload
        issue = Signal()
        handed = Signal()
        accepted = Signal()
        m.d.comb += handed.eq(self.planes.valid & self.planes.ready)
        m.d.sync += [reserved.eq(reserved + Mux(issue, burst, 0) - handed),
                     owed.eq(owed + Mux(accepted, request.row_count * port_words_per_row, 0)
                             - (handed & (owed != 0)))]
        with m.If(lost | zero):
            m.d.sync += reserved.eq(0)
        with m.If(lost):
            m.d.sync += zero.eq(1)
        with m.Elif((owed == 0) & ~accepted):
            m.d.sync += zero.eq(0)

        # every word in the read FIFO has room in ours (reserved covers it): take it at once
        arriving = fifo.w_stream
        m.d.comb += [
            port.rd_en.eq(port.calib_done & ~port.rd_empty),
            arriving.valid.eq(port.rd_en & ~lost & ~zero),     # (none come: the MCB dropped them)
            arriving.payload.eq(port.rd_data),
            port.cmd_instr.eq(mcb.Instr.READ),
            port.cmd_bl.eq(burst - 1),
            port.cmd_byte_addr.eq(address),
            port.cmd_en.eq(issue),
            port.wr_en.eq(0),
        ]

        # the run of rows being gathered: rows from one slot, contiguous in memory
        slot, plane = Signal(SLOT_BITS), Signal(3)
        row = Signal(range(dmd.rows + 1))        # the row whose lookup is on ``sources`` now
        left = Signal(range(dmd.rows + 1))       # rows of the request from ``row`` on
        run_source, run_first = Signal(SLOT_BITS), Signal(range(dmd.rows))
        run_rows = Signal(range(dmd.rows + 1))
        src = self.sources
        m.d.comb += [src.slot.eq(slot), src.row.eq(row)]

        with m.FSM():
            with m.State("IDLE"):
                # (answering zeros: one request at a time)
                m.d.comb += self.requests.ready.eq(~zero | (owed == 0))
                m.d.comb += [src.slot.eq(request.slot), src.row.eq(request.first_row)]
                with m.If(self.requests.valid & self.requests.ready):      # (not while answering zeros)
                    fits = ((request.slot < self._slots) & (request.row_count != 0)
                            & (request.first_row + request.row_count <= dmd.rows))
                    with m.If(fits):
                        m.d.comb += accepted.eq(1)
                        m.d.sync += [slot.eq(request.slot), plane.eq(request.plane), row.eq(request.first_row),
                                     left.eq(request.row_count), run_rows.eq(0)]
                        m.next = "GATHER"
                        with m.If(lost | zero):
                            m.next = "IDLE"            # answered as zeros
                    with m.Else():
                        m.d.sync += self.bad_requests.eq(self.bad_requests + 1)
            with m.State("LOOK"):
                m.next = "GATHER"                      # ``row`` is looked up
                with m.If(lost):
                    m.next = "IDLE"
            with m.State("GATHER"):
                whole = ~src.delta
                joins = (run_rows == 0) | (src.source == run_source)
                with m.If(lost):
                    m.next = "IDLE"
                with m.Elif(joins):
                    with m.If(run_rows == 0):
                        m.d.sync += [run_source.eq(Mux(whole, slot, src.source)), run_first.eq(row)]
                    taken = Mux(whole, left, 1)        # a whole frame's request is one run
                    m.d.sync += [run_rows.eq(run_rows + taken), left.eq(left - taken), row.eq(row + taken)]
                    m.d.comb += src.row.eq(row + 1)
                    with m.If(left == taken):
                        m.next = "PREPARE"
                with m.Else():
                    m.next = "PREPARE"                 # ``row`` starts the next run
            with m.State("PREPARE"):
                m.d.sync += [
                    address.eq(self._map.address(run_source, plane, run_first)),
                    remaining.eq(run_rows * port_words_per_row),
                    run_rows.eq(0),
                ]
                m.next = "ISSUE"
                with m.If(lost):
                    m.next = "IDLE"
            with m.State("ISSUE"):
                with m.If(lost):
                    m.next = "IDLE"                    # the rest of the request is answered as zeros
                with m.Elif(port.calib_done & ~port.cmd_full & (reserved + burst <= depth)):
                    m.d.comb += issue.eq(1)
                    m.d.sync += [address.eq(address + burst * (words * WORD_BYTES)),
                                 remaining.eq(remaining - burst)]
                    with m.If(remaining == burst):
                        m.next = "IDLE"
                        with m.If(left != 0):
                            m.next = "LOOK"
        if self._domain != "sync":
            return DomainRenamer({"sync": self._domain})(m)
        return m
