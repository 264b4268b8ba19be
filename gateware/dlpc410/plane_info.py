"""What each group's next pulse does, worked out ahead of it.

When a group pulses, the planner must know at once whether the plane it ends is its frame's last,
whether the plane is long enough to hide the next plane's load (``hide``), and how long until the
group's next pulse: the plane's time (the frame's least significant plane's time, shifted by the
plane's weight; a gated plane's, ``gated_time``), or for a dark pulse the dark gap (at a frame's
end, the frame's own dark time if longer). These take a shift and 40-bit comparisons, too much
for the cycle of a decision; but a
group's position and frame change only when it pulses (or every group's, when the frame control
starts or retakes a frame), and its next pulse comes long after. So one pipeline works them out
for each group in turn and keeps the answers per group; an answer is ``fresh`` once it was
worked out from the group's state as it is now.

A group's next pulse is never decided before its answers are fresh (the planner's ``due`` waits
for it): at most ``blocks + STAGES`` cycles after a change, far less than any plane or dark gap a
plan gives (at least ``t_rst + t_settle``).
"""

from amaranth import Array, Module, Mux, Signal
from amaranth.lib import data, wiring
from amaranth.lib.wiring import In, Out

from ..limbs import greater, limb_order
from ..registers import DURATION_BITS, Registers
from .group_frames import FRAME
from .timebase import exponents, group_tables, order_position

__all__ = ["PlaneInfo", "STAGES"]

#: Cycles from a group's state to its answers.
STAGES = 7


class PlaneInfo(wiring.Component):
    """Per-group answers for the next pulse (``sync``).

    Parameters
    ----------
    dmd : :class:`spec.facts.DmdType`

    Members
    -------
    regs : In(:class:`~gateware.registers.Registers`)
        ``order``, ``order_table``, ``group_tables``, ``anchor``, ``lsb``, ``hide``, ``dark_gap``,
        ``gated_planes``, ``gated_time``.
    pos : In(ArrayLayout(3, blocks)); dark : In(blocks); frame : In(ArrayLayout(FRAME, blocks))
        Each group's display position, whether its next pulse is a dark one, and its frame.
    changed : In(blocks)
        Bit g: group g's state changes this cycle (its answers are stale from now).
    last : Out(blocks)
        Bit g: the group's position is its frame's last plane.
    big : Out(blocks)
        Bit g: the plane at the group's position lasts at least ``hide``.
    keeps_dark : Out(blocks)
        Bit g: the group's frame asks for no dark time of its own.
    delay : Out(ArrayLayout(DURATION_BITS, blocks))
        Per group, the time from its next pulse to the one after: the plane's time, or for a
        dark pulse the dark gap (at the last plane, the frame's dark time if longer).
    fresh : Out(blocks)
        Bit g: the answers for group g follow from its state as it is.
    exponent : Out(3)
        The weight exponent of the plane at group 0's position (the light gate's: gating is
        global, one group).
    """

    def __init__(self, dmd):
        self._dmd = dmd
        blocks = dmd.blocks
        super().__init__({
            "regs": In(Registers),
            "pos": In(data.ArrayLayout(3, blocks)),
            "dark": In(blocks),
            "frame": In(data.ArrayLayout(FRAME, blocks)),
            "changed": In(blocks),
            "last": Out(blocks),
            "big": Out(blocks),
            "keeps_dark": Out(blocks),
            "delay": Out(data.ArrayLayout(DURATION_BITS, blocks)),
            "fresh": Out(blocks),
            "exponent": Out(3),
        })

    def elaborate(self, platform):
        m = Module()
        regs, blocks = self.regs, self._dmd.blocks
        frame = FRAME

        # one group a cycle, in turn
        turn = Signal(range(blocks))
        m.d.sync += turn.eq(Mux(turn == blocks - 1, 0, turn + 1))
        # each stage's group and whether its state is still the group's: a change applied on a
        # cycle (seen registered, the cycle after) makes every stage of that group stale that
        # read its state then or before (stages 0-5; the answers are kept from stage 5, STAGES
        # cycles after the state was read, unless the group changes on that cycle too)
        tags = [Signal(range(blocks), name=f"tag{k}") for k in range(STAGES - 1)]
        valid = [Signal(name=f"valid{k}") for k in range(STAGES - 1)]
        changed = Signal(blocks)
        m.d.sync += changed.eq(self.changed)
        changed = Array(changed)

        def advance(k):
            """Stage k's tag and validity from stage k - 1's (killed if its group changed)."""
            m.d.sync += [tags[k].eq(tags[k - 1]), valid[k].eq(valid[k - 1] & ~changed[tags[k - 1]])]

        # 0: the group's state
        pos, dark, depth = Signal(3), Signal(), Signal(4)
        show = Signal(data.Layout.cast(frame)["showing"].shape)
        table = Signal(24)
        m.d.sync += [tags[0].eq(turn), valid[0].eq(1), table.eq(group_tables(regs, blocks)[turn]),
                     pos.eq(Array(self.pos)[turn]), dark.eq(self.dark.bit_select(turn, 1)),
                     depth.eq(Array(f.depth for f in self.frame)[turn]),
                     show.eq(Array(f.showing for f in self.frame)[turn])]

        # 1: the plane's position in the order (from the anchor) and the exponent at each
        # position (of the group's table, picked at 0), the least significant plane's time; the last plane
        advance(1)
        at = Signal(3)
        lsb = Signal.like(regs.lsb)
        last0, dark0 = Signal(), Signal()
        edark0 = Signal.like(show.dark)
        nodark0 = Signal()
        each = Signal(data.ArrayLayout(3, 8))
        m.d.sync += [at.eq(order_position(m, regs, pos, depth, "info_at")),
                     each.eq(exponents(m, regs, depth, "info_exps", table)),
                     lsb.eq(show.lsb_or(regs.lsb)), last0.eq(pos == depth - 1),
                     dark0.eq(dark), edark0.eq(show.dark), nodark0.eq(show.dark == 0)]

        # 2: the plane's weight, and whether it is gated
        advance(2)
        e = each[at]
        gated1 = Signal()
        m.d.sync += gated1.eq(regs.gated_planes.bit_select(e, 1))
        last1, dark1, nodark1 = Signal(), Signal(), Signal()
        edark1 = Signal.like(show.dark)
        lsb1 = Signal.like(regs.lsb)
        e1 = Signal(3)
        m.d.sync += [e1.eq(e), lsb1.eq(lsb), last1.eq(last0), dark1.eq(dark0), edark1.eq(edark0),
                     nodark1.eq(nodark0)]

        # 3: the plane's time
        advance(3)
        plane = Signal(DURATION_BITS)
        last2, dark2, nodark2 = Signal(), Signal(), Signal()
        edark2 = Signal(DURATION_BITS)
        e2, e3, e4 = Signal(3), Signal(3), Signal(3)
        m.d.sync += [e2.eq(e1), e3.eq(e2), e4.eq(e3)]
        m.d.sync += [plane.eq(Mux(gated1, regs.gated_time, lsb1 << e1)), last2.eq(last1), dark2.eq(dark1),
                     nodark2.eq(nodark1),
                     edark2.eq(edark1)]

        # 4: the comparisons, a limb at a time
        advance(4)
        big_above, big_same = limb_order(m, plane, regs.hide, "big")
        long_above, long_same = limb_order(m, edark2, regs.dark_gap, "long")
        plane3, edark3 = Signal(DURATION_BITS), Signal(DURATION_BITS)
        last3, dark3, nodark3 = Signal(), Signal(), Signal()
        m.d.sync += [plane3.eq(plane), edark3.eq(edark2), last3.eq(last2), dark3.eq(dark2), nodark3.eq(nodark2)]

        # 5: the answers (and the group they are for, one-hot: each group's keep is one LUT)
        advance(5)
        hot = Signal(blocks)
        m.d.sync += hot.eq(1 << tags[4])
        big, last4, nodark4 = Signal(), Signal(), Signal()
        delay = Signal(DURATION_BITS)
        m.d.sync += [big.eq(greater(big_above, big_same, or_equal=True)), last4.eq(last3), nodark4.eq(nodark3),
                     delay.eq(Mux(dark3, Mux(last3 & greater(long_above, long_same), edark3, regs.dark_gap),
                                  plane3))]

        # kept per group
        for g in range(blocks):
            with m.If(valid[-1] & hot[g] & ~changed[g]):
                m.d.sync += [self.last[g].eq(last4), self.big[g].eq(big), self.keeps_dark[g].eq(nodark4),
                             self.delay[g].eq(delay), self.fresh[g].eq(1)]
                if g == 0:
                    m.d.sync += self.exponent.eq(e4)
            with m.If(self.changed[g]):
                m.d.sync += self.fresh[g].eq(0)
        return m
