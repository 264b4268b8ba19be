"""The load jobs: what a group must be loaded with next, after its pulse or when its first plane
is queued.

The cycle after a pulse is applied, the group's new state (its frame, display position, dark)
is registered as a job; a first plane queued (the frame taken next, position 0) replaces it in
that cycle. Its position in the plane order (counted from the anchor register), and the exponent
at each position of the order, are worked out on the stage after; the stored plane it reads (its
position's exponent above the frame's lowest stored plane) on the next; then the job leaves.
"""

from amaranth import Cat, Module, Signal
from amaranth.lib import data, wiring
from amaranth.lib.wiring import In, Out

from ..registers import Registers
from .group_frames import FRAME
from .layouts import event, group_bits, load_job
from .timebase import exponents, group_tables, order_position, stored_plane

__all__ = ["LoadJobs"]


class LoadJobs(wiring.Component):
    """Load jobs from the groups' state (``sync``).

    Parameters
    ----------
    dmd : :class:`spec.facts.DmdType`

    Members
    -------
    regs : In(:class:`~gateware.registers.Registers`)
        ``order``, ``order_table``, ``group_tables``, ``anchor``.
    pulse : In(blocks); pulse_any : In(1)
        Bit g: group g's pulse is applied now (one bit at most); some bit of ``pulse``.
    pos : In(ArrayLayout(3, blocks)); dark : In(blocks); frame : In(ArrayLayout(FRAME, blocks))
        Each group's display position, whether its next pulse is a dark one, and its frame.
    queue_first : In(event(group)); next : In(FRAME)
        Queue the group's first plane of ``next``, the frame taken next.
    jobs : Out(event(load_job))
        Load jobs, three cycles after their pulse or their queueing.
    due : Out(1)
        A job is on its way (it leaves within three cycles).
    """

    def __init__(self, dmd):
        self._dmd = dmd
        blocks = dmd.blocks
        super().__init__({
            "regs": In(Registers),
            "pulse": In(blocks),
            "pulse_any": In(1),
            "pos": In(data.ArrayLayout(3, blocks)),
            "dark": In(blocks),
            "frame": In(data.ArrayLayout(FRAME, blocks)),
            "queue_first": In(event(group_bits(dmd))),
            "next": In(FRAME),
            "jobs": Out(event(load_job(dmd))),
            "due": Out(1),
        })

    def elaborate(self, platform):
        m = Module()
        dmd, blocks, group_index_bits = self._dmd, self._dmd.blocks, group_bits(self._dmd)
        job = Signal(load_job(dmd))
        low_plane = Signal(3)                  # the job's frame's lowest stored plane
        table = Signal(24)                     # the job's group's order table (GROUPS)
        tables = group_tables(self.regs, blocks)
        pulsed, group, formed = Signal(), Signal(group_index_bits), Signal()
        m.d.sync += [pulsed.eq(self.pulse_any),
                     # the pulsed group's index, bit by bit
                     group.eq(Cat(Cat(self.pulse[g] for g in range(blocks) if g >> b & 1).any()
                                  for b in range(group_index_bits))),
                     formed.eq(pulsed | self.queue_first.valid)]
        with m.If(pulsed):
            kept = self.frame[group]
            m.d.sync += [job.group.eq(group), job.slot.eq(kept.slot), job.depth.eq(kept.depth),
                         low_plane.eq(kept.low_plane), job.pos.eq(self.pos[group]), table.eq(tables[group]),
                         job.clear.eq(self.dark.bit_select(group, 1))]
        with m.If(self.queue_first.valid):
            m.d.sync += [job.group.eq(self.queue_first.payload), job.slot.eq(self.next.slot),
                         job.depth.eq(self.next.depth), low_plane.eq(self.next.low_plane), job.pos.eq(0),
                         table.eq(tables[self.queue_first.payload]),
                         job.clear.eq(0)]
        # the job's position in the plane order (the anchor's rotation) and the exponent at each
        # position, then its stored plane
        staged, staged_low, at, ordered = Signal(load_job(dmd)), Signal(3), Signal(3), Signal()
        each = Signal(data.ArrayLayout(3, 8))
        m.d.sync += [ordered.eq(formed), staged.eq(job), staged_low.eq(low_plane),
                     at.eq(order_position(m, self.regs, job.pos, job.depth, "job_at")),
                     each.eq(exponents(m, self.regs, job.depth, "job_exps", table))]
        out, valid = Signal(load_job(dmd)), Signal()
        m.d.sync += [valid.eq(ordered), out.eq(staged), out.plane.eq(stored_plane(staged_low, each[at]))]
        m.d.comb += [self.jobs.valid.eq(valid), self.jobs.payload.eq(out),
                     self.due.eq(pulsed | formed | ordered | valid)]
        return m
