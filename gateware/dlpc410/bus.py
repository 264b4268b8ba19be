"""The command bus: one decision every even cycle on which no row cycle runs.

The DLPC410 runs at DCLK/2, so idle gaps are even: the bus decides on even cycles only, once the
row cycle before (and a clear's no-op rows) leaves room for the next on the pins. It makes, in
this order of priority:

1. A clocking pulse of a due group (the lowest such group), if the strict RST_ACTIVE reading's
   pin allows it.
2. Else the next clear of the oldest dark pulse's group, once that group's memory may change. A
   dark load needs no data and its deadline is the shortest plane's, so it overtakes the loads
   queued before it.
3. Else the next operation of the ready load at the head: a row of an occupied block,
   ``row_period`` after the last row and with a whole row of beats buffered, or a clear of an
   empty block. It goes only if that group's memory may change, and if the oldest dark pulse's
   group's memory does not free before the operation would end (its clears would wait for it).
4. Else nothing.

A load or clear goes only if no loaded group's pulse falls due before it would end. A load whose
row data has not arrived is counted as an underrun (one per row that waits, however long).

The decision is made from registered flags (the planner's, the bus's own) and registered; the
cycle after, it is applied: the command registers (the pins show it :data:`DECISION_TO_PINS`
cycles after the decision), the pulse event, the load's progress. (The operation is registered
as chosen without the pulses, and a pulse decided with it takes its place as it is applied.) A
load's last operation ends the group's load on the cycle before the next decision may be made.
Where the load at the head, and the dark's clears, have got to is kept by :class:`LoadCursor`.
"""

from amaranth import Array, Cat, Const, Module, Mux, Signal
from amaranth.lib import data, stream, wiring
from amaranth.lib.wiring import In, Out

from spec.schedule import DECISION_TO_PINS, row_cycles

from ..countdown import Countdown
from ..counter import Counter
from ..registers import Registers, ResetMode
from .due import lowest_due
from .interface import BlockMode, RowMode
from .layouts import COUNTER_BITS, Command, PulseSignature, block_bits, dark_load, group_bits, ready_load

__all__ = ["Bus", "LoadCursor", "DECISION_TO_PINS"]


def _decision(dmd):
    """The bus's decision, registered: whether it pulses (and which group), loads a row or clears
    a block (a dark's clear, the load's last operation), for which group, block and row; and, for
    the load's operation after it, where that one will stand."""
    group_index_bits, block_index_bits = group_bits(dmd), block_bits(dmd)
    return data.StructLayout({
        "pulse": 1, "pulse_group": group_index_bits, "row": 1, "clear": 1, "dark": 1, "last": 1,
        "load_group": dmd.blocks, "block": block_index_bits, "row_at": 11, "fresh": 1, "starved": 1,
        "block_last": 1, "following": block_index_bits, "following_last": 1, "following_filled": 1})


class Bus(wiring.Component):
    """Arbitration between pulses and loads, and the command registers.

    Parameters
    ----------
    dmd : :class:`spec.facts.DmdType`
        A clear takes ``clear_row_cycles`` row cycles (the clear, then no-op rows with DVALID
        high).
    beats : int
        DCLK beats per cycle: a row cycle is ``dclk_per_row // beats`` cycles.

    Members
    -------
    regs : In(Registers)
    even : In(1)
        An even cycle of the time base.
    running, flushing : In(1)
        From the frame control: no decision before the groups run; ready loads are dropped
        while flushing.
    hold : In(1)
        The frame control takes a frame (applied now): no load is started.
    restart : In(1)
        The frame control takes a frame while waiting: the next load starts afresh.
    rst_active : In(1)
        RST_ACTIVE, synchronised: with ``strict_rst`` no pulse while it is high.
    planner : In(PulseSignature(blocks))
        The planner's flags (registered; ``frees_soon`` includes ``writable``), and this cycle's
        decision back to it: ``choice`` (bit g, a clocking pulse of group g), ``pulsing`` (some
        bit of ``choice``) and ``loaded`` (bit g: group g's load ends this cycle, its last
        operation's last row cycle on the pins by the next decision).
    loads : In(stream.Signature(ready_load))
        Ready loads from the requester, taken when their last operation is applied.
    darks : In(stream.Signature(dark_load))
        The clears a dark pulse needs, in the order of the pulses, taken when their last clear is
        applied.
    beats : In(stream.Signature(bits_per_dclk * beats)); row_ready : In(1)
        Row data, one cycle's beats taken per cycle of a row cycle that loads a row; whether a
        whole row is buffered.
    row_started : Out(1)
        The first beat of a row is taken this cycle.
    dvalid : Out(1); command : Out(Command); beat : Out(bits_per_dclk * beats)
        The registered pins of the row cycles.
    underruns : Out(COUNTER_BITS)
        Row loads that waited for their data (one each, however long).
    """

    def __init__(self, dmd, *, beats=1):
        self._dmd, self._beats = dmd, beats
        super().__init__({
            "regs": In(Registers),
            "even": In(1),
            "running": In(1),
            "flushing": In(1),
            "hold": In(1),
            "restart": In(1),
            "rst_active": In(1),
            "planner": In(PulseSignature(dmd.blocks)),
            "loads": In(stream.Signature(ready_load(dmd))),
            "darks": In(stream.Signature(dark_load(dmd))),
            "beats": In(stream.Signature(dmd.bits_per_dclk * beats)),
            "row_ready": In(1),
            "row_started": Out(1),
            "dvalid": Out(1),
            "command": Out(Command),
            "beat": Out(dmd.bits_per_dclk * beats),
            "underruns": Out(COUNTER_BITS),
        })

    def elaborate(self, platform):
        m = Module()
        dmd, regs = self._dmd, self.regs
        cycles_per_row = row_cycles(dmd, self._beats)
        blocks = dmd.blocks
        block_index_bits = block_bits(dmd)
        clear_cycles = dmd.clear_row_cycles * cycles_per_row

        # after an operation is applied: cycles until the next decision may be made (the next
        # operation's pins may follow its pins back to back)
        remain = Signal(range(clear_cycles))
        spent = Signal(init=1)                 # ``remain`` is 0 (registered with it)
        # a decision on every other cycle: ``even``, and (should the time base stall, as it does
        # while the controller initialises) never on two cycles running
        was_free = Signal()
        free = spent & self.even & self.running & ~was_free
        m.d.sync += was_free.eq(free)

        # ---- pulses: the lowest due group, if the pin allows it ----
        pin_ok = ~(regs.strict_rst & self.rst_active)
        due, fours = self.planner.due, self.planner.due_fours
        pulse_choice = Signal(blocks)
        m.d.comb += pulse_choice.eq(Mux(free & pin_ok, lowest_due(due, fours), 0))
        do_pulse = free & pin_ok & fours.any()
        m.d.comb += [self.planner.choice.eq(pulse_choice), self.planner.pulsing.eq(do_pulse)]

        # ---- loads: the operation at the head ----
        # (the head's first operation, or the next of a load under way, and the dark's next clear)
        head, dark = self.loads.payload, self.darks.payload
        m.submodules.cursor = cursor = LoadCursor(dmd)
        m.d.comb += [cursor.head.eq(head), cursor.dark.eq(dark), cursor.restart.eq(self.restart)]
        operation, clear_block = cursor.operation, cursor.clear_block
        m.submodules.pace = pace = Countdown(8, lag=1, flags="settled")
        # (one AND of the flags each: the head's group may change, ...; chosen as if no pulse
        # were due, the pulse's priority applied from the registered decision, so that the due
        # flags' priority is not in series with the operation's conditions)
        may_op = free & ~self.flushing & ~self.hold
        # ---- a dark pulse's clears first, once its group's memory may change ----
        dark_ready = self.darks.valid & self.planner.writable.bit_select(dark.group, 1)
        do_dark = may_op & dark_ready & ~self.planner.imminent_clear
        # a load operation waits while the dark's clears go first, or would wait for it (the
        # ``frees_soon`` flags include ``writable``: one choice by the dark's group, not two)
        can_load = may_op & self.loads.valid & self.planner.writable.bit_select(head.group, 1)
        dark_soon = self.darks.valid & self.planner.frees_soon.bit_select(dark.group, 1)
        dark_soon_clear = self.darks.valid & self.planner.frees_soon_clear.bit_select(dark.group, 1)
        wants_row = can_load & ~self.planner.imminent & ~dark_soon & operation.occupied & pace.done
        do_row = wants_row & self.row_ready
        do_clear = (can_load & ~self.planner.imminent_clear & ~dark_soon_clear & ~operation.occupied) | do_dark

        # ---- the decision, registered ----
        decision = Signal(_decision(dmd))
        following = (operation.block + 1)[:block_index_bits]
        m.d.sync += [decision.pulse.eq(do_pulse), decision.pulse_group.eq(_lowest(due, fours)),
                     decision.row.eq(do_row), decision.clear.eq(do_clear), decision.dark.eq(dark_ready),
                     decision.last.eq(Mux(dark_ready, clear_block == dark.last, operation.last)),
                     decision.load_group.eq(1 << Mux(dark_ready, dark.group, head.group)),
                     decision.block.eq(Mux(dark_ready, clear_block, operation.block)),
                     decision.row_at.eq(operation.row_at), decision.fresh.eq(operation.fresh),
                     decision.starved.eq(wants_row & ~self.row_ready),
                     # (for the operation after it)
                     decision.block_last.eq(operation.block == head.last), decision.following.eq(following),
                     decision.following_last.eq(following == head.last),
                     decision.following_filled.eq(head.mask.bit_select(following, 1))]

        # ---- applied ----
        # (a pulse goes first: the operation was chosen as if none were due)
        row, clear, starved = Signal(), Signal(), Signal()
        m.d.comb += [row.eq(decision.row & ~decision.pulse), clear.eq(decision.clear & ~decision.pulse),
                     starved.eq(decision.starved & ~decision.pulse)]
        op = row | clear
        m.d.comb += [pace.load.eq(row), pace.value.eq(regs.row_period),
                     cursor.decision.eq(decision), cursor.row.eq(row), cursor.clear.eq(clear),
                     self.loads.ready.eq(cursor.load_taken), self.darks.ready.eq(cursor.dark_taken)]
        with m.If(self.flushing):
            m.d.comb += [self.loads.ready.eq(1), self.darks.ready.eq(1)]

        # a row counts once however many cycles it waits for its data
        waiting = Signal()
        with m.If(starved):
            m.d.sync += waiting.eq(1)
        with m.If(row):
            m.d.sync += waiting.eq(0)
        m.submodules.underruns = underruns = Counter(COUNTER_BITS)
        m.d.comb += [underruns.inc.eq(starved & ~waiting), self.underruns.eq(underruns.count)]

        # the group's load ends on the cycle before its last operation leaves room for the next
        # decision: a two-cycle operation's now, a longer one's registered the cycle before
        length_two = Mux(clear, clear_cycles == 2, cycles_per_row == 2)
        finishing = Signal(blocks)                  # this group's load ends at ``remain == 1``
        ends = Signal(blocks)                       # the load of this group ends next cycle
        with m.If(op & decision.last & ~length_two):
            m.d.sync += finishing.eq(decision.load_group)
        with m.If(remain == 2):
            m.d.sync += [finishing.eq(0), ends.eq(finishing)]
        with m.Else():
            m.d.sync += ends.eq(0)
        with m.If(self.restart):
            m.d.sync += [finishing.eq(0), ends.eq(0)]
        m.d.comb += self.planner.loaded.eq(ends | Mux(op & decision.last & length_two, decision.load_group, 0))

        # ---- the command registers ----
        self._command_registers(m, decision, row, clear, remain=remain, spent=spent)
        return m

    def _command_registers(self, m, decision, row, clear, *, remain, spent):
        """The pins of the decision ``decision`` (``row``, ``clear``: it loads a row, clears a block),
        from the cycle after it: the command held through its row cycles (a clear's no-op rows
        after it), DVALID, the row's beats; and ``remain``, the cycles until the next decision may
        be made (``spent``: none)."""
        dmd, regs = self._dmd, self.regs
        op = row | clear
        cycles_per_row = row_cycles(dmd, self._beats)
        clear_cycles = dmd.clear_row_cycles * cycles_per_row
        # the pins' row cycle: the cycles of the row still to come, a thermometer code (bit i:
        # more than i), so that whether there are more is a register and the row's beats are
        # read through one LUT
        row_left = Signal(cycles_per_row - 1)
        more = row_left[0] if cycles_per_row > 1 else Const(0)
        whole_row = (1 << (cycles_per_row - 1)) - 1
        noops = Signal(range(dmd.clear_row_cycles))
        cmd = self.command
        op_row = Signal()                      # the row cycle on the pins loads a row
        reading = row | (op_row & more)
        m.d.comb += [self.beats.ready.eq(reading), self.row_started.eq(row)]
        m.d.sync += self.beat.eq(Mux(reading, self.beats.payload, 0))
        with m.If(remain != 0):
            m.d.sync += [remain.eq(remain - 1), spent.eq(remain == 1)]
        with m.If(decision.pulse | op):
            length = Mux(clear, clear_cycles, cycles_per_row)
            m.d.sync += [self.dvalid.eq(1), remain.eq(length - 2), spent.eq(length == 2), row_left.eq(whole_row),
                         op_row.eq(row), noops.eq(Mux(clear, dmd.clear_row_cycles - 1, 0)),
                         cmd.rowmd.eq(RowMode.NOOP), cmd.blkmd.eq(BlockMode.NOOP),
                         cmd.rowad.eq(0), cmd.blkad.eq(0), cmd.rst2blkz.eq(1)]
            with m.If(row):
                m.d.sync += [cmd.rowmd.eq(RowMode.ADDRESSED), cmd.rowad.eq(decision.row_at)]
            with m.Elif(clear):
                m.d.sync += [cmd.blkmd.eq(BlockMode.CLEAR), cmd.blkad.eq(decision.block)]
            with m.Else():
                p = decision.pulse_group
                with m.Switch(regs.reset_mode):
                    with m.Case(ResetMode.GLOBAL):
                        m.d.sync += [cmd.blkmd.eq(BlockMode.MULTI), cmd.blkad.eq(0b1000)]
                    with m.Case(ResetMode.QUAD):
                        m.d.sync += [cmd.blkmd.eq(BlockMode.MULTI), cmd.blkad.eq(p << 1)]
                    with m.Case(ResetMode.DUAL):
                        m.d.sync += [cmd.blkmd.eq(BlockMode.MULTI), cmd.blkad.eq(p), cmd.rst2blkz.eq(0)]
                    with m.Case(ResetMode.SINGLE):
                        m.d.sync += [cmd.blkmd.eq(BlockMode.RESET), cmd.blkad.eq(p)]
        with m.Elif(more):
            m.d.sync += row_left.eq(row_left[1:])
        with m.Elif(noops != 0):
            # the clear's no-op rows follow it back to back (1080p), DVALID high
            m.d.sync += [row_left.eq(whole_row), noops.eq(noops - 1), cmd.blkmd.eq(BlockMode.NOOP), cmd.blkad.eq(0)]
        with m.Else():
            m.d.sync += [self.dvalid.eq(0), op_row.eq(0), cmd.rowmd.eq(RowMode.NOOP),
                         cmd.blkmd.eq(BlockMode.NOOP), cmd.rst2blkz.eq(1)]


class LoadCursor(wiring.Component):
    """Where the ready load at the head of its queue, and the dark pulse's clears at the head of
    theirs, have got to: the next operation of each, worked out as the operation before it is
    applied, so that the bus decides from registers.

    Parameters
    ----------
    dmd : :class:`spec.facts.DmdType`

    Members
    -------
    head : In(ready_load)
        The ready load at the head of its queue.
    dark : In(dark_load)
        The dark pulse's clears at the head of their queue.
    decision : In(StructLayout)
        The bus's decision of the cycle before (:func:`_decision`), applied now.
    row, clear : In(1)
        The operation applied now loads a row, clears a block (a pulse took the place of neither).
    restart : In(1)
        The next operations are the loads' first (the frame control takes a frame while waiting).
    operation : Out(StructLayout(fresh, block, occupied, last, row_at))
        The head load's next operation: whether it is the load's first, its block, whether it
        loads a row of that block (else it clears the block), whether it is the load's last, and
        its row's address (rows are numbered block after block).
    clear_block : Out(block_bits)
        The block the dark's next clear clears.
    load_taken, dark_taken : Out(1)
        The head load's, the dark's last operation is applied now: its queue may let it go.
    """

    def __init__(self, dmd):
        self._dmd = dmd
        block_index_bits = block_bits(dmd)
        super().__init__({
            "head": In(ready_load(dmd)),
            "dark": In(dark_load(dmd)),
            "decision": In(_decision(dmd)),
            "row": In(1),
            "clear": In(1),
            "restart": In(1),
            "operation": Out(data.StructLayout({"fresh": 1, "block": block_index_bits, "occupied": 1, "last": 1,
                                                "row_at": 11})),
            "clear_block": Out(block_index_bits),
            "load_taken": Out(1),
            "dark_taken": Out(1),
        })

    def elaborate(self, platform):
        m = Module()
        rows_per_block = self._dmd.rows_per_block
        block_index_bits = block_bits(self._dmd)
        head, dark, decision, row, operation = self.head, self.dark, self.decision, self.row, self.operation
        # the head's next operation once the load is under way (while ``fresh``, the head's first)
        fresh = Signal(init=1)
        load_block = Signal(block_index_bits)
        load_row = Signal(range(rows_per_block))
        load_occupied = Signal()
        load_last = Signal()
        row_at = Signal(11)
        dark_fresh = Signal(init=1)               # the dark's first block is next
        dark_block = Signal(block_index_bits)
        m.d.comb += [operation.fresh.eq(fresh), operation.block.eq(Mux(fresh, head.first, load_block)),
                     operation.occupied.eq(Mux(fresh, head.first_occupied, load_occupied)),
                     operation.last.eq(Mux(fresh, head.single, load_last)),
                     operation.row_at.eq(Mux(fresh, head.first_row, row_at)),
                     self.clear_block.eq(Mux(dark_fresh, dark.first, dark_block))]
        with m.If(self.clear & decision.dark):
            with m.If(decision.last):
                m.d.comb += self.dark_taken.eq(1)
                m.d.sync += dark_fresh.eq(1)
            with m.Else():
                m.d.sync += [dark_fresh.eq(0), dark_block.eq(decision.block + 1)]
        with m.Elif(row | self.clear):
            with m.If(decision.last):
                m.d.comb += self.load_taken.eq(1)
                m.d.sync += fresh.eq(1)
            with m.Else():
                m.d.sync += fresh.eq(0)
                at_row = Mux(decision.fresh, 0, load_row)
                with m.If(row & (at_row != rows_per_block - 1)):
                    # the block's next row
                    m.d.sync += [load_block.eq(decision.block), load_row.eq(at_row + 1), load_occupied.eq(1),
                                 load_last.eq(decision.block_last & (at_row == rows_per_block - 2))]
                with m.Else():
                    # the next block: its rows, or a clear
                    m.d.sync += [load_block.eq(decision.following), load_row.eq(0),
                                 load_occupied.eq(decision.following_filled),
                                 load_last.eq(decision.following_last
                                              & (~decision.following_filled | (rows_per_block == 1)))]
            # rows are numbered block after block: the next row follows this one, or the next
            # block's first row follows a cleared block's
            m.d.sync += row_at.eq(decision.row_at + Mux(row, 1, rows_per_block))
        with m.If(self.restart):
            m.d.sync += [fresh.eq(1), dark_fresh.eq(1)]
        return m


def _lowest(bits, fours):
    """The index of the lowest set bit of ``bits`` (up to 16; 0 when none), ``fours`` saying
    which chunk of four has one: each chunk's lowest bit, then the lowest chunk that has (so a
    LUT for each, and a four-way choice)."""
    assert len(bits) <= 16 and len(fours) == -(-len(bits) // 4)
    if len(bits) <= 4:
        return _lowest_of_four(bits)
    lows = Array(_lowest_of_four(bits[lo:lo + 4]) for lo in range(0, len(bits), 4))
    first = _lowest_of_four(fours)
    return Cat(lows[first], first)


def _lowest_of_four(bits):
    index = Const(0, 2)
    for i in reversed(range(len(bits))):
        index = Mux(bits[i], i, index)
    return index
