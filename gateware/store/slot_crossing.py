"""The sequencer's side of the frame slots: asks and releases into ``sync``, answers into ``dmd``.

Asks and releases share one FIFO, so that the slot table sees them in the order the sequencer
gave them (a release behind an ask that cannot be answered yet waits for it).
"""

from amaranth import Module, Signal
from amaranth.lib import data, stream, wiring
from amaranth.lib.fifo import AsyncFIFO
from amaranth.lib.wiring import In, Out

from .layouts import SLOT_BITS, FrameInfo

__all__ = ["SlotCrossing", "Command"]


class Command(data.Struct):
    """From the sequencer: an ask (``release`` = 0), or the release of slot ``slot``."""
    release: 1
    slot: SLOT_BITS


class SlotCrossing(wiring.Component):
    """Clock-domain crossing of the sequencer's asks, releases and answers.

    Parameters
    ----------
    depth : int
        Commands and answers each FIFO holds.

    Members
    -------
    ask : In(stream.Signature(0))
        Each transfer asks for one frame (``dmd``).
    release : In(stream.Signature(SLOT_BITS))
        Slots the sequencer hands back (``dmd``); a release goes before an ask offered at the
        same time.
    frames : Out(stream.Signature(FrameInfo))
        The answers (``dmd``).
    commands : Out(stream.Signature(Command))
        Asks and releases in order (``sync``).
    answers : In(stream.Signature(FrameInfo))
        Answers to the asks (``sync``).
    """

    def __init__(self, *, depth=4):
        self._depth = depth
        super().__init__({
            "ask": In(stream.Signature(0)),
            "release": In(stream.Signature(SLOT_BITS)),
            "frames": Out(stream.Signature(FrameInfo)),
            "commands": Out(stream.Signature(Command)),
            "answers": In(stream.Signature(FrameInfo)),
        })

    def elaborate(self, platform):
        m = Module()
        m.submodules.commands = commands = AsyncFIFO(width=Command.as_shape().size, depth=self._depth,
                                                    w_domain="dmd", r_domain="sync")
        m.submodules.answers = answers = AsyncFIFO(width=FrameInfo.as_shape().size, depth=self._depth,
                                                   w_domain="sync", r_domain="dmd")
        wiring.connect(m, commands.r_stream, wiring.flipped(self.commands))
        wiring.connect(m, wiring.flipped(self.answers), answers.w_stream)
        wiring.connect(m, answers.r_stream, wiring.flipped(self.frames))

        # Releases go first, but an ask offered to the full FIFO stays offered until it is taken
        # (a stream's payload does not change before its transfer).
        merged = stream.Signature(Command).create()
        ask_offered = Signal()
        release_first = Signal()
        m.d.comb += [
            release_first.eq(self.release.valid & ~ask_offered),
            merged.valid.eq(self.ask.valid | self.release.valid),
            merged.payload.release.eq(release_first),
            self.release.ready.eq(merged.ready & ~ask_offered),
            self.ask.ready.eq(merged.ready & ~release_first),
        ]
        with m.If(release_first):
            m.d.comb += merged.payload.slot.eq(self.release.payload)
        m.d.dmd += ask_offered.eq(merged.valid & ~merged.ready & ~release_first)
        wiring.connect(m, merged, commands.w_stream)
        return m
