"""A periodic trigger faster than the frames it starts.

With :attr:`~gateware.registers.TriggerMode.PERIODIC`, a frame whose planes alone (its ``lsb`` times
``2**depth - 1`` cycles, the least any plan gives them) outlast ``period`` cannot end before the
next strobe: that strobe is then held or an overrun (``trigger_hold``), and the triggers no
longer come at the period the user set. The frame is still shown; each such frame is counted,
so that the status reply says why. (A period shorter than ``lsb`` fits no frame at all: the
sequencer record is dropped instead, :func:`spec.records.register_faults`.)
"""

from amaranth import Module, Signal
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from ..counter import Counter
from ..limbs import greater, limb_order, limbs, pipelined_sum
from ..registers import DURATION_BITS, LSB_BITS, Registers, TriggerMode
from .layouts import COUNTER_BITS

__all__ = ["PeriodWatch"]


class PeriodWatch(wiring.Component):
    """Count frames started by the periodic timer that last longer than its period.

    Members
    -------
    regs : In(:class:`~gateware.registers.Registers`)
        ``trigger``, ``period``.
    depth, lsb : In(4), In(LSB_BITS)
        Bit depth and least significant plane's time of the frame the first group plays; they
        are set at least a plane before that frame's first pulse.
    frame_start : In(1)
        A frame's first pulse.
    short : Out(COUNTER_BITS)
        Frames started in periodic mode whose planes outlast the period.
    """
    regs: In(Registers)
    depth: In(4)
    lsb: In(LSB_BITS)
    frame_start: In(1)
    short: Out(COUNTER_BITS)

    def elaborate(self, platform):
        m = Module()
        regs = self.regs
        # registered stages, a limb at a time: the depth and the registers are steady for a plane
        # or more before the frame's first pulse (a shift, a difference, a comparison)
        depth, lsb, shifted = Signal(4), Signal(DURATION_BITS), Signal(DURATION_BITS)
        m.d.sync += [depth.eq(self.depth), lsb.eq(self.lsb), shifted.eq(lsb << depth)]
        planes, _ = pipelined_sum(m, [shifted] * len(limbs(DURATION_BITS)), lambda k: ~lsb, 1, "planes")
        above, same = limb_order(m, planes[:DURATION_BITS], regs.period, "planes")
        too_short = Signal()
        m.d.sync += too_short.eq((regs.trigger == TriggerMode.PERIODIC) & greater(above, same))
        m.submodules.count = count = Counter(COUNTER_BITS)
        m.d.comb += [count.inc.eq(self.frame_start & too_short), self.short.eq(count.count)]
        return m
