"""The command bus: one decision every even cycle on which no row cycle runs.

The DLPC410 runs at DCLK/2, so idle gaps are even: the bus decides on even cycles only, once the
row cycle before (and a clear's no-op rows) has ended. It makes, in this order of priority: a
clocking pulse of a group that is due (the lowest such group), else the next load operation of
the ready load at the head (a row of an occupied block, ``row_period`` after the last row and
with a whole row of beats buffered; or a clear of an empty block), if that group's settle time
is over and no loaded group's pulse falls due before the operation would end; else nothing. A
load whose row data has not arrived is counted as an underrun (one per decision that waits).
"""

from amaranth import Module, Mux, Signal
from amaranth.lib import stream, wiring
from amaranth.lib.wiring import In, Out
from amaranth.utils import ceil_log2

from spec.schedule import row_cycles

from ..registers import TIME_BITS, Registers, ResetMode
from .interface import BlockMode, RowMode
from .layouts import COUNTER_BITS, Command, event, group_bits, ready_load
from .timebase import diff

__all__ = ["Bus"]


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
    now : In(TIME_BITS)
    running, flushing : In(1)
        From the frame control: no decision before the groups run; ready loads are dropped
        while flushing.
    restart : In(1)
        The frame control takes a frame while waiting: the next load starts afresh.
    due, writable : In(blocks); imminent, imminent_clear : In(1)
        From the planner.
    loads : In(stream.Signature(ready_load))
        Ready loads from the requester, taken when their last operation is made.
    beats : In(stream.Signature(bits_per_dclk * beats)); row_ready : In(1)
        Row data, one cycle's beats taken per cycle of a row cycle that loads a row.
    pulse : Out(event(group))
        A clocking pulse of this group is made this cycle.
    loaded : Out(event(group))
        This group's load ended this cycle (its last operation's last row cycle).
    dvalid : Out(1); command : Out(Command); beat : Out(bits_per_dclk * beats)
        The registered pins of the row cycles.
    underruns : Out(COUNTER_BITS)
        Decisions that waited for row data.
    """

    def __init__(self, dmd, *, beats=1):
        self._dmd, self._beats = dmd, beats
        gb = group_bits(dmd)
        super().__init__({
            "regs": In(Registers),
            "now": In(TIME_BITS),
            "running": In(1),
            "flushing": In(1),
            "restart": In(1),
            "due": In(dmd.blocks),
            "writable": In(dmd.blocks),
            "imminent": In(1),
            "imminent_clear": In(1),
            "loads": In(stream.Signature(ready_load(dmd))),
            "beats": In(stream.Signature(dmd.bits_per_dclk * beats)),
            "row_ready": In(1),
            "pulse": Out(event(gb)),
            "loaded": Out(event(gb)),
            "dvalid": Out(1),
            "command": Out(Command),
            "beat": Out(dmd.bits_per_dclk * beats),
            "underruns": Out(COUNTER_BITS),
        })

    def elaborate(self, platform):
        m = Module()
        dmd, regs, now = self._dmd, self.regs, self.now
        R = row_cycles(dmd, self._beats)
        rpb = dmd.rows_per_block
        gb = group_bits(dmd)

        remain = Signal(range(R))              # cycles of the running row cycle after this one
        noops = Signal(range(dmd.clear_row_cycles))   # no-op rows still owed to a clear
        free = (remain == 0) & ~now[0] & (noops == 0)
        op_row = Signal()                      # the running row cycle loads a row
        finishing = Signal()
        finish_group = Signal(gb)

        # ---- pulses: the lowest due group ----
        p = Signal(gb)
        for g in reversed(range(dmd.blocks)):
            with m.If(self.due[g]):
                m.d.comb += p.eq(g)
        do_pulse = Signal()
        m.d.comb += [do_pulse.eq(self.running & free & self.due.any()),
                     self.pulse.valid.eq(do_pulse), self.pulse.payload.eq(p)]

        # ---- loads: the operation at the head ----
        head = self.loads.payload
        fresh = Signal(init=1)
        l_block = Signal(ceil_log2(dmd.blocks) or 1)
        l_row = Signal(range(rpb))
        cur_block = Mux(fresh, head.first, l_block)
        cur_row = Mux(fresh, 0, l_row)
        occupied = head.mask.bit_select(cur_block, 1)
        next_row_at = Signal(TIME_BITS)
        can_load = (self.running & ~self.flushing & free & ~do_pulse & self.loads.valid
                    & self.writable.bit_select(head.group, 1))
        row_paced = diff(next_row_at, now) <= 0
        do_row = Signal()
        do_clear = Signal()
        m.d.comb += [
            do_row.eq(can_load & ~self.imminent & occupied & row_paced & self.row_ready),
            do_clear.eq(can_load & ~self.imminent_clear & ~occupied),
        ]
        last_op = (cur_block == head.last) & (~occupied | (cur_row == rpb - 1))
        with m.If(can_load & ~self.imminent & occupied & row_paced & ~self.row_ready):
            m.d.sync += self.underruns.eq(self.underruns + 1)

        with m.If(do_row | do_clear):
            with m.If(last_op):
                m.d.comb += self.loads.ready.eq(1)
                m.d.sync += [fresh.eq(1), finishing.eq(1), finish_group.eq(head.group)]
            with m.Else():
                m.d.sync += fresh.eq(0)
                with m.If(occupied & (cur_row != rpb - 1)):
                    m.d.sync += [l_block.eq(cur_block), l_row.eq(cur_row + 1)]
                with m.Else():
                    m.d.sync += [l_block.eq(cur_block + 1), l_row.eq(0)]
        with m.If(do_row):
            m.d.sync += next_row_at.eq(now + regs.row_period)
        with m.If(finishing & (remain == 1) & (noops == 0)):
            m.d.comb += [self.loaded.valid.eq(1), self.loaded.payload.eq(finish_group)]
            m.d.sync += finishing.eq(0)
        with m.If(self.flushing):
            m.d.comb += self.loads.ready.eq(1)
        with m.If(self.restart):
            m.d.sync += [fresh.eq(1), finishing.eq(0)]

        # ---- the command registers ----
        cmd = self.command
        reading = do_row | (op_row & (remain != 0))
        m.d.comb += self.beats.ready.eq(reading)
        m.d.sync += self.beat.eq(Mux(reading, self.beats.payload, 0))
        with m.If(do_pulse | do_row | do_clear):
            m.d.sync += [self.dvalid.eq(1), remain.eq(R - 1), op_row.eq(do_row),
                         cmd.rowmd.eq(RowMode.NOOP), cmd.blkmd.eq(BlockMode.NOOP),
                         cmd.rowad.eq(0), cmd.blkad.eq(0), cmd.rst2blkz.eq(1)]
            with m.If(do_row):
                m.d.sync += [cmd.rowmd.eq(RowMode.ADDRESSED), cmd.rowad.eq(cur_block * rpb + cur_row)]
            with m.Elif(do_clear):
                m.d.sync += [cmd.blkmd.eq(BlockMode.CLEAR), cmd.blkad.eq(cur_block),
                             noops.eq(dmd.clear_row_cycles - 1)]
            with m.Else():
                with m.Switch(regs.reset_mode):
                    with m.Case(ResetMode.GLOBAL):
                        m.d.sync += [cmd.blkmd.eq(BlockMode.MULTI), cmd.blkad.eq(0b1000)]
                    with m.Case(ResetMode.QUAD):
                        m.d.sync += [cmd.blkmd.eq(BlockMode.MULTI), cmd.blkad.eq(p << 1)]
                    with m.Case(ResetMode.DUAL):
                        m.d.sync += [cmd.blkmd.eq(BlockMode.MULTI), cmd.blkad.eq(p), cmd.rst2blkz.eq(0)]
                    with m.Case(ResetMode.SINGLE):
                        m.d.sync += [cmd.blkmd.eq(BlockMode.RESET), cmd.blkad.eq(p)]
        with m.Elif(remain != 0):
            m.d.sync += remain.eq(remain - 1)
        with m.Elif(noops != 0):
            # the clear's no-op rows follow it back to back (1080p), DVALID high
            m.d.sync += [remain.eq(R - 1), noops.eq(noops - 1), cmd.blkmd.eq(BlockMode.NOOP), cmd.blkad.eq(0)]
        with m.Else():
            m.d.sync += [self.dvalid.eq(0), op_row.eq(0), cmd.rowmd.eq(RowMode.NOOP),
                         cmd.blkmd.eq(BlockMode.NOOP), cmd.rst2blkz.eq(1)]
        return m
