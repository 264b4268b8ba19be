"""The camera trigger: a pulse of ``camera_width`` cycles, ``camera_offset`` after a frame starts."""

from amaranth import Module, Signal
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from ..registers import TIME_BITS, Registers
from .timebase import diff

__all__ = ["CameraTrigger"]


class CameraTrigger(wiring.Component):
    """Camera-trigger output.

    Members
    -------
    regs : In(Registers)
        ``camera_offset``, ``camera_width``.
    now : In(TIME_BITS)
    frame_start : In(1)
        The bus makes a frame's first clocking pulse this cycle.
    out : Out(1)
        Registered like the command pins: the pulse leaves ``camera_offset`` cycles after the
        frame's first clocking pulse leaves.
    """

    regs: In(Registers)
    now: In(TIME_BITS)
    frame_start: In(1)
    out: Out(1)

    def elaborate(self, platform):
        m = Module()
        regs, now = self.regs, self.now
        at = Signal(TIME_BITS)
        armed = Signal()
        end = at + regs.camera_width
        with m.If(self.frame_start):
            m.d.sync += [at.eq(now + regs.camera_offset), armed.eq(1)]
        with m.Elif(armed & (diff(now, end) >= 0)):
            m.d.sync += armed.eq(0)
        # an offset of 0 starts the pulse with the frame, before ``at`` is registered
        starts_now = self.frame_start & (regs.camera_offset == 0) & (regs.camera_width != 0)
        m.d.sync += self.out.eq(starts_now | (armed & (diff(now, at) >= 0) & (diff(now, end) < 0)))
        return m
