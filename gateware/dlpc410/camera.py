"""The camera trigger: a pulse of ``camera_width`` cycles, ``camera_offset`` after a frame starts.

Two countdowns (:mod:`gateware.countdown`), the width's loaded as the offset's ends: the pulse
starts and ends on their last cycles, with no sum formed.
"""

from amaranth import Module, Signal
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from ..countdown import Countdown
from ..registers import DURATION_BITS, Registers

__all__ = ["CameraTrigger"]


class CameraTrigger(wiring.Component):
    """Camera-trigger output.

    Members
    -------
    regs : In(Registers)
        ``camera_offset``, ``camera_width``.
    frame_start : In(1)
        A frame's first clocking pulse is applied this cycle (its command reaches the pins the
        next cycle).
    out : Out(1)
        Registered like the command pins: the pulse leaves ``camera_offset`` cycles after the
        frame's first clocking pulse leaves (a frame starting meanwhile starts it again).
    """

    regs: In(Registers)
    frame_start: In(1)
    out: Out(1)

    def elaborate(self, platform):
        m = Module()
        regs = self.regs
        m.submodules.offset = offset = Countdown(DURATION_BITS, flags="given")
        m.submodules.width = width = Countdown(16, flags="settled")
        none = Signal()                        # a pulse of no cycles: nothing to send
        m.d.sync += none.eq(regs.camera_width == 0)
        # (the values hold still: their countdowns' flags are worked out ahead, the offset's in
        # two stages, and whether it is 0 from its limbs' zero flags)
        offset_flags = offset.flags_registered(m, regs.camera_offset, "offset_flags")
        at_once = offset_flags.zero.all()
        waiting, pulsing = Signal(), Signal()
        starts = waiting & offset.ends
        m.d.comb += [offset.value.eq(regs.camera_offset), offset.load_flags.eq(offset_flags),
                     width.value.eq(regs.camera_width)]
        with m.If(self.frame_start):
            m.d.comb += [offset.load.eq(~at_once), width.load.eq(at_once)]
            m.d.sync += [waiting.eq(~at_once), pulsing.eq(at_once & ~none), self.out.eq(at_once & ~none)]
        with m.Elif(starts):
            m.d.comb += width.load.eq(1)
            m.d.sync += [waiting.eq(0), pulsing.eq(~none), self.out.eq(~none)]
        with m.Elif(pulsing & width.ends):
            m.d.sync += [pulsing.eq(0), self.out.eq(0)]
        return m
