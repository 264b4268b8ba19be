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

Look-ahead: the reader keeps issuing commands, across request boundaries, as long as a whole
burst fits in its FIFO beside the words it has asked for and not yet handed on (``fifo_depth``
plane words, several commands outstanding), so the memory's latency is hidden and a port word
per ``dmd`` cycle leaves whenever the memory delivers that fast. Because those words always have
room, the reader takes every word from the MCB's read FIFO as soon as it is there: that FIFO
never overflows.

A request that does not fit the frame (slot beyond the slots, no rows, rows past the last) is
dropped and counted; it produces no words.

A lost memory (``store_lost``, from :mod:`gateware.store.recovery`): the MCB has dropped the
commands and words in flight, so the reader puts a zero word in its FIFO for each word it had
asked for and not received, and answers the rest of its requests, and every request taken until
the store has recovered, with zeros (its commands go to no memory); the sequencer is never left
waiting for words that will not come, and gets the words read before the loss first.

Pipeline (every path between flip-flops within the ``dmd`` budget of :mod:`flow.timing`): a
request is taken into registers (``IDLE``), its first row looked up and its sums formed
(``CHECK``), then checked and gathered into runs (``GATHER``, :mod:`.runs`); a run's address is its slot's
start (a table of the slots) plus its plane's, summed into a register as the run's slot is
chosen, plus its rows' offset as the run is loaded, and its bursts are counted down in
registers; the counts of words asked for and owed step by a burst and a word in one carry chain
each. A request's first command leaves three cycles after it is taken (``valid`` and ``ready``
both high), and a word from the memory reaches ``planes`` three cycles after the MCB offers it.
"""

import math

from amaranth import Cat, Const, DomainRenamer, Module, Mux, Signal
from amaranth.lib import stream, wiring
from amaranth.lib.memory import Memory
from amaranth.lib.wiring import In, Out
from amaranth.utils import exact_log2

from . import mcb
from .addresses import PLANES, AddressMap
from .layouts import SLOT_BITS, PlaneRequest
from .read_fifo import ReadFifo
from .runs import Runs
from .slot_maps import RowLookupSignature

__all__ = ["Reader", "RunStart"]


def _trailing_zeros(n):
    return (n & -n).bit_length() - 1


class RunStart(wiring.Component):
    """A run's first port word, summed as the run's slot is chosen (``sync``).

    A run starts at its slot's start (a table of the slots, read from a register: the table's
    LUTs, no more) plus its plane's (a table of 8) plus its rows' offset. Every start is a multiple
    of ``2**low`` port words, so each sum is one carry chain above the low bits, in a stage of its
    own: the slot's and plane's starts are summed here, a cycle or more before the run is given;
    the reader adds the rows' offset as it loads the run. (With the memory full of slots, up to
    256, each chain is at most 16 bits for the DLP7000, the DLP9500 and the test geometries through
    either port, 17 for the DLP650LNIR's past 65 slots.)

    Parameters
    ----------
    address_map : :class:`~gateware.store.addresses.AddressMap`
        Where the slots and planes lie.
    word_bytes : int
        Bytes in a port word.
    plane_words : int
        Port words in a plane.

    Attributes
    ----------
    low : int
        The low bits of a port word's address that every start has zero.
    address_bits : int
        Bits of a port word's address.

    Members
    -------
    slot : In(SLOT_BITS)
        The slot of the run being opened; no run is of a slot past the table (a request for one
        is dropped, and the row map names the store's slots only).
    plane : In(3)
        The run's plane: the request's, the same from the cycle the run is opened on.
    load : In(1)
        The run is opened: its start is summed at the end of this cycle.
    start : Out(address_bits - low)
        The run's start above the low bits, from the cycle after ``load``.
    """

    def __init__(self, address_map, word_bytes, plane_words):
        assert address_map.base % word_bytes == 0
        self.low = _trailing_zeros(math.gcd(address_map.base // word_bytes, plane_words))
        self.address_bits = (address_map.end // word_bytes - 1).bit_length()
        self._slot_starts = [address_map.address(slot, 0) // word_bytes >> self.low
                             for slot in range(address_map.slots)]
        self._plane_starts = [plane * plane_words >> self.low for plane in range(PLANES)]
        super().__init__({
            "slot": In(SLOT_BITS),
            "plane": In(3),
            "load": In(1),
            "start": Out(self.address_bits - self.low),
        })

    def elaborate(self, platform):
        m = Module()
        width = self.address_bits - self.low
        m.submodules.slot_starts = table = Memory(shape=width, depth=len(self._slot_starts), init=self._slot_starts)
        slot_start = table.read_port(domain="comb")
        plane_start = Signal(width)
        with m.Switch(self.plane):
            for plane, value in enumerate(self._plane_starts):
                with m.Case(plane):
                    m.d.comb += plane_start.eq(value)
        m.d.comb += slot_start.addr.eq(self.slot)
        with m.If(self.load):
            m.d.sync += self.start.eq(slot_start.data + plane_start)
        return m


class Reader(wiring.Component):
    """Read runs of plane rows from DDR2 into a FIFO.

    Parameters
    ----------
    dmd : :class:`spec.facts.DmdType`
    slots : int
        Frame slots in the memory (the address map).
    fifo_depth : int
        Plane words of look-ahead and buffering (a power of two, a multiple of 64 port words;
        256 = four commands of a 64-bit port, or two of a 128-bit port, in flight).
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
    sources : Out(RowLookupSignature(dmd, "source"))
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
            "sources": Out(RowLookupSignature(dmd, "source")),
        })

    def elaborate(self, platform):
        m = Module()
        dmd, port = self._dmd, self.mcb
        word_bytes = port.signature.word_bytes
        depth = self._fifo_depth * 64 // self._width           # port words
        row_words = dmd.words_per_row * 64 // self._width      # port words per row
        plane_words = dmd.rows * row_words
        burst_bits = exact_log2(mcb.MAX_BURST)

        # Addresses in port words: a run's start above the low bits that every start has zero
        # (:class:`RunStart`), plus its rows' offset as the run is loaded; a burst of 64 steps the
        # bits above the burst's, in two halves (below; a half is at most 9 bits).
        starts = RunStart(self._map, word_bytes, plane_words)
        low, address_bits = starts.low, starts.address_bits

        # ---- the words: the memory's (or zeros) through a FIFO to the sequencer ----------------
        m.submodules.fifo = fifo = ReadFifo(self._width, depth)
        wiring.connect(m, fifo.r_stream, wiring.flipped(self.planes))

        lost = self.store_lost
        zero = Signal()                          # lost since, and words still owed
        fill = lost | zero                       # answer with zeros
        issue, bl = Signal(), Signal(burst_bits)  # a command (its port words less one) goes
        arrived = Signal()                       # a word goes into the FIFO
        handed = Signal()                        # a word went on to the sequencer last cycle
        # Port words asked for (or answered as zeros) and not yet handed on, and asked for and not
        # yet in the FIFO. Each steps by bl + 1 at an issue and back by one at an event, as one
        # sum with the event in its carry: count + (bl, or -1) + (1, or 0).
        count_bits = depth.bit_length()
        used, owed = Signal(count_bits), Signal(count_bits)
        step = Mux(issue, bl, (1 << count_bits) - 1)
        m.d.sync += [
            handed.eq(self.planes.valid & self.planes.ready),   # (registered: ``ready`` stops here)
            used.eq(used + step + ~handed),
            owed.eq(owed + step + ~arrived),
        ]
        # Every word in the read FIFO has room in ours (``used`` covers it): take it at once. Lost,
        # none come (the MCB dropped them): a zero word is put in for each owed instead, at most
        # every other cycle, so that whether one is owed is a flag a cycle old (no word came since).
        owing, came = Signal(), Signal()
        m.d.sync += [owing.eq(owed != 0), came.eq(arrived)]
        m.d.comb += [
            port.rd_en.eq(port.calib_done & ~port.rd_empty),
            arrived.eq(Mux(fill, owing & ~came, port.rd_en)),
            fifo.w_stream.valid.eq(arrived),
            fifo.w_stream.payload.eq(Mux(fill, 0, port.rd_data)),
        ]

        # ---- the commands: one run of rows at a time, in bursts of up to 64 port words --------
        issuing = Signal()                       # a run is loaded
        address = Signal(address_bits)
        last_bl = Signal(burst_bits)             # the run's last burst, less one
        before_last = Signal(range(((plane_words - 1) >> burst_bits) + 1))     # bursts before it
        is_last = Signal()
        # Room for a burst of any length (the FIFO's word count needs no sum with the burst's), as a
        # flag a cycle old: it holds while no command went since (``handed`` only makes room), so
        # a command goes at most every other cycle, and its decision is one LUT of flip-flops.
        room, issued = Signal(), Signal()
        m.d.sync += [room.eq(used <= depth - mcb.MAX_BURST), issued.eq(issue)]
        m.d.comb += [
            bl.eq(Mux(is_last, last_bl, mcb.MAX_BURST - 1)),
            issue.eq(issuing & room & ~issued & (fill | (port.calib_done & ~port.cmd_full))),
            port.cmd_en.eq(issue & ~fill),
            port.cmd_instr.eq(mcb.Instr.READ),
            port.cmd_bl.eq(bl),
            port.cmd_byte_addr.eq(Cat(Const(0, exact_log2(word_bytes)), address)),
            port.wr_en.eq(0),
        ]
        # A burst steps the bits above the burst's in two parts, a carry chain each: the low part
        # at the command, the high part the cycle after with the low part's carry out. No command
        # goes in that cycle (``issued``) and no run is loaded (``issuing`` holds after a burst
        # that is not the run's last), so the address is whole again before it is used.
        steps = address[burst_bits:]
        split = len(steps) // 2
        carry = Signal()
        if split:
            with m.If(carry):
                m.d.sync += [steps[split:].eq(steps[split:] + 1), carry.eq(0)]
        with m.If(issue):
            with m.If(is_last):
                m.d.sync += issuing.eq(0)
            with m.Else():
                m.d.sync += [before_last.eq(before_last - 1), is_last.eq(before_last == 1)]
                if split:
                    m.d.sync += Cat(steps[:split], carry).eq(steps[:split] + 1)
                else:
                    m.d.sync += steps.eq(steps + 1)

        # ---- requests into runs (:mod:`.runs`), each loaded into the above when given ----------
        m.submodules.runs = runs = Runs(dmd, slots=self._slots, row_words=row_words, max_burst=mcb.MAX_BURST)
        wiring.connect(m, wiring.flipped(self.requests), runs.requests)
        wiring.connect(m, runs.sources, wiring.flipped(self.sources))
        m.d.comb += [runs.busy.eq(issuing), self.bad_requests.eq(runs.bad_requests)]
        run = runs.run
        m.submodules.run_start = starts
        m.d.comb += [starts.slot.eq(runs.next_slot), starts.plane.eq(run.plane), starts.load.eq(runs.loads)]
        run_last = run.words - 1
        with m.If(runs.emit):
            m.d.sync += [
                issuing.eq(1),
                address[:low].eq(run.off[:low]),
                address[low:].eq(starts.start + run.off[low:]),
                last_bl.eq(run_last[:burst_bits]),
                before_last.eq(run_last[burst_bits:]),
                is_last.eq(run.single),
            ]

        # answering with zeros from the loss until the store has recovered and nothing is owed,
        # between requests (one taken in that very cycle is taken after the recovery: it is read)
        with m.If(lost):
            m.d.sync += zero.eq(1)
        with m.Elif(runs.idle & ~issuing & (owed == 0)):
            m.d.sync += zero.eq(0)
        if self._domain != "sync":
            return DomainRenamer({"sync": self._domain})(m)
        return m
