"""The plane reader's requests, gathered into runs of rows that are contiguous in memory.

A request names a slot, a plane and a run of rows. A whole frame's request is one run; a delta
frame's rows may show its base's words, so its rows are looked up in the row map (one a cycle)
and each stretch of rows from one slot becomes a run. A request that does not fit the frame (a
slot beyond the slots, no rows, rows past the last) is dropped and counted.

The steps of a request, a flag each (one-hot: a decision on the step is a LUT input of its own,
not a state to decode): IDLE takes it; CHECK looks its first row up and forms its sums; GATHER
has the first row's answer: a whole frame's request is one run, a delta's WALKs its rows one a
cycle, a run for each stretch of rows from one slot, and FLUSHes the last run.
"""

from amaranth import Module, Signal
from amaranth.lib import data, stream, wiring
from amaranth.lib.wiring import In, Out
from amaranth.utils import ceil_log2

from ..counter import Counter
from .layouts import SLOT_BITS, PlaneRequest
from .slot_maps import RowLookupSignature

__all__ = ["Runs", "run_layout"]


def run_layout(plane_words):
    """A run of rows: ``words`` port words from ``off`` of plane ``plane`` of slot ``slot``;
    ``single``: they fit one burst."""
    return data.StructLayout({"slot": SLOT_BITS, "plane": 3, "off": range(plane_words),
                              "words": range(plane_words + 1), "single": 1})


def _times(value, factor):
    """``value * factor`` as shifts of ``value``, at most two of them added or subtracted: one
    carry chain at most, never a multiplier (``factor``: a row's port words)."""
    terms, shift = [], 0
    while factor:
        if factor & 1:
            digit = 2 - (factor & 3)           # the non-adjacent form: +1 or -1
            terms.append((digit, value << shift))
            factor -= digit
        factor >>= 1
        shift += 1
    assert 1 <= len(terms) <= 2, "a row's port words: a power of two, or the sum or difference of two"
    terms.sort(key=lambda term: -term[0])      # the positive term first
    result = terms[0][1]
    for digit, term in terms[1:]:
        result = result + term if digit > 0 else result - term
    return result


class Runs(wiring.Component):
    """Requests into runs (one clock domain, ``sync``).

    Parameters
    ----------
    dmd : :class:`spec.facts.DmdType`
    slots : int
        Frame slots in the memory.
    row_words : int
        Port words per row.
    max_burst : int
        Port words of the longest read command (``single``).

    Members
    -------
    requests : In(stream.Signature(PlaneRequest))
        What to read.
    sources : Out(RowLookupSignature(dmd, "source"))
        The row map: which slot each row of a slot shows, and whether the slot holds a delta.
    busy : In(1)
        The commands still hold the run before: no run is given.
    emit : Out(1); run : Out(run_layout)
        A run is given now (held until then).
    loads : Out(1); next_slot : Out(SLOT_BITS)
        A run is opened: ``run.slot`` becomes ``next_slot`` (a register) at the end of this cycle,
        a cycle or more before the run is given, so that what a table holds for the slot, read
        into a register when ``loads``, is there beside ``run.slot``.
    idle : Out(1)
        No request under way (one is taken now if offered).
    bad_requests : Out(16)
        Requests dropped because they do not fit the frame.
    """

    def __init__(self, dmd, *, slots, row_words, max_burst):
        self._dmd, self._slots, self._row_words, self._max_burst = dmd, slots, row_words, max_burst
        super().__init__({
            "requests": In(stream.Signature(PlaneRequest)),
            "sources": Out(RowLookupSignature(dmd, "source")),
            "busy": In(1),
            "emit": Out(1),
            "run": Out(run_layout(dmd.rows * row_words)),
            "loads": Out(1),
            "next_slot": Out(SLOT_BITS),
            "idle": Out(1),
            "bad_requests": Out(16),
        })

    def elaborate(self, platform):
        m = Module()
        dmd, src, row_words, max_burst = self._dmd, self.sources, self._row_words, self._max_burst
        plane_words = dmd.rows * row_words
        taken = Signal(PlaneRequest)
        run = Signal(run_layout(plane_words))  # (its plane is the request's)
        m.d.comb += [self.run.eq(run), self.run.plane.eq(taken.plane)]

        # the request fits the frame: a slot of the store and some rows, none past the last
        # (two flags: each is a short path from the request's registers)
        some, within = Signal(), Signal()
        look = Signal(ceil_log2(dmd.rows))       # the row looked up on ``sources``
        # the row decided on (a delta's walk: two behind ``look``): its offset in port words,
        # the request's rows from it on, and whether it is the request's last
        row_off = Signal(range(plane_words))
        left = Signal(range(dmd.rows + 1))
        last = Signal()
        run_open = Signal()
        # the row map's answers a stage later, for a delta's walk: the row's source, and whether
        # the row before showed the same (so that the walk decides from registers alone); while a
        # request is checked, its own slot (the slot of its run as one: ``next_slot`` is always
        # this register, and neither answer is used before the walk's first row is decided)
        row_source, same = Signal(SLOT_BITS), Signal()
        m.d.comb += [src.slot.eq(taken.slot), src.row.eq(look)]
        with m.If(src.en):
            # (every lookup steps on to the next row, but while a delta's row waits)
            m.d.sync += [look.eq(look + 1), row_source.eq(src.source), same.eq(src.source == row_source)]
        m.submodules.bad = bad = Counter(16)
        m.d.comb += self.bad_requests.eq(bad.count)

        idle = Signal(init=1)
        check, gather, walk, flush = Signal(), Signal(), Signal(), Signal()
        request = self.requests.payload
        whole = ~src.delta
        fits = some & within
        joins = run_open & same
        busy = self.busy
        # a row that ends the run before it waits (the row map's answers held) until the commands
        # take that run
        advance = joins | ~run_open | ~busy
        m.d.comb += [
            self.idle.eq(idle),
            self.requests.ready.eq(idle),
            src.en.eq(~walk | advance),
            bad.inc.eq(gather & ~fits),
            self.emit.eq(~busy & (gather & fits & whole | walk & run_open & ~same | flush)),
            # a run opens: the request's (its slot taken), or a delta's row that starts one
            self.loads.eq(check | walk & advance & ~joins),
            self.next_slot.eq(row_source),
        ]
        with m.If(self.loads):
            m.d.sync += run.slot.eq(self.next_slot)
        m.d.sync += [
            idle.eq(idle & ~self.requests.valid | gather & ~fits | gather & whole & ~busy | flush & ~busy),
            check.eq(idle & self.requests.valid),
            gather.eq(check | gather & fits & whole & busy),
            walk.eq(gather & fits & ~whole | walk & ~(advance & last)),
            flush.eq(walk & advance & last | flush & busy),
        ]
        with m.If(idle):
            # (every cycle: nothing uses them before a request is taken)
            m.d.sync += [taken.eq(request), look.eq(request.first_row), row_source.eq(request.slot)]
        with m.If(check):
            first, count = taken.first_row, taken.row_count
            m.d.sync += [
                some.eq((taken.slot < self._slots) & (count != 0)), within.eq(first + count <= dmd.rows),
                row_off.eq(_times(first, row_words)), left.eq(count), last.eq(count == 1),
                # the request as one run (a whole frame's; its slot: ``loads``)
                run.off.eq(_times(first, row_words)),
                run.words.eq(_times(count, row_words)), run.single.eq(count <= max_burst // row_words),
                run_open.eq(0),
            ]
        with m.If(walk & advance):
            m.d.sync += [row_off.eq(row_off + row_words), left.eq(left - 1), last.eq(left == 2), run_open.eq(1)]
            with m.If(joins):
                m.d.sync += [run.words.eq(run.words + row_words),
                             run.single.eq(run.words <= max_burst - row_words)]
            with m.Else():
                m.d.sync += [run.off.eq(row_off), run.words.eq(row_words),
                             run.single.eq(row_words <= max_burst)]
        return m
