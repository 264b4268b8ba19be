"""The frame each pulse group shows: its slot, bit depth, lowest stored plane and entry settings,
and the newest frame taken, which a group takes next.

The first group to move on to a new frame takes the frame offered (``take``; in one timeline
group 0, in GROUPS whichever ends its frame first); the others take the newest one taken when
they move on (``advance``); a start or a retake gives every group, and the next frame, one frame
(``every``).
"""

from amaranth import Module, Mux, Signal
from amaranth.lib import data, wiring
from amaranth.lib.wiring import In, Out

from ..store.layouts import SLOT_BITS, Showing
from .layouts import event

__all__ = ["GroupFrames", "FRAME"]

#: A frame as a group shows it: ``depth`` planes from stored plane ``low_plane`` up.
FRAME = data.StructLayout({"slot": SLOT_BITS, "depth": 4, "low_plane": 3, "showing": Showing})

#: The entry settings each group keeps of its frame (its follow flag is only read of the frame
#: taken next).
_KEPT = ("lsb", "dark", "camera_off", "last")


class GroupFrames(wiring.Component):
    """Per-group frames (``sync``).

    Parameters
    ----------
    dmd : :class:`spec.facts.DmdType`

    Members
    -------
    frame : Out(ArrayLayout(FRAME, blocks))
        Each group's frame (its ``showing.follow`` is 0: not kept).
    next : Out(FRAME)
        The newest frame taken.
    offered : In(FRAME); take : In(1)
        The frame offered; it is taken now (the next frame from the next cycle).
    coming : Out(FRAME)
        The frame a group moving on now takes: the one offered if it is taken, else ``next``.
    advance : In(blocks)
        Bit g: group g moves on to ``coming`` (from registered flags: its plane information is
        still the decision's).
    active : In(blocks)
        Bit g: group g is one of the reset mode's.
    first : Out(blocks)
        Bit g: no group has moved on from the frame group g shows: it is the first to, and takes
        the frame offered (registered: pulses are decided at least two cycles apart, so a move
        applied now is counted in by the next decision).
    every : In(event(FRAME))
        Every group, and the next frame, take this frame (after ``advance`` and ``take``).
    """

    def __init__(self, dmd):
        self._dmd = dmd
        blocks = dmd.blocks
        super().__init__({
            "frame": Out(data.ArrayLayout(FRAME, blocks)),
            "next": Out(FRAME),
            "offered": In(FRAME),
            "take": In(1),
            "coming": Out(FRAME),
            "advance": In(blocks),
            "active": In(blocks),
            "first": Out(blocks),
            "every": In(event(FRAME)),
        })

    def elaborate(self, platform):
        m = Module()
        blocks = self._dmd.blocks
        next_frame = Signal(FRAME)
        m.d.comb += [self.next.eq(next_frame),
                     self.coming.eq(Mux(self.take, self.offered.as_value(), next_frame.as_value()))]

        def give(g, frame):
            kept = self.frame[g]
            return [kept.slot.eq(frame.slot), kept.depth.eq(frame.depth), kept.low_plane.eq(frame.low_plane),
                    *(kept.showing[name].eq(frame.showing[name]) for name in _KEPT)]
        for g in range(blocks):
            with m.If(self.advance[g]):
                m.d.sync += give(g, self.coming)
        with m.If(self.take):
            m.d.sync += next_frame.eq(self.offered)
        # groups still showing the frame before ``next``: set for the others when one leads
        behind = Signal(blocks)
        led = (self.advance & ~behind).any()
        m.d.comb += self.first.eq(~behind)
        for g in range(blocks):
            m.d.sync += behind[g].eq(~self.every.valid & ~self.advance[g] & Mux(led, self.active[g], behind[g]))
        with m.If(self.every.valid):
            m.d.sync += next_frame.eq(self.every.payload)
            for g in range(blocks):
                m.d.sync += give(g, self.every.payload)
        return m
