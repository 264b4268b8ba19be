"""The frame the store offers, as the sequencer's decisions read it: registered.

The store offers its newest complete frame on a stream. Its offer is registered (the decisions
that read it start from flip-flops, :data:`spec.schedule.OFFER_LAG`), and free to take unless a
take is being answered; a frame taken is answered while the store still offers it (a stream
holds its payload until the transfer), and one with a bit depth the sequencer does not play is
dropped at once, and counted.
"""

from amaranth import Module, Signal
from amaranth.lib import data, stream, wiring
from amaranth.lib.wiring import In, Out

from ..counter import Counter
from ..store.layouts import SLOT_BITS, FrameInfo, Showing
from .layouts import COUNTER_BITS

__all__ = ["FrameOffer", "Offer"]


class Offer(data.Struct):
    """The frame the store offers now: ``valid`` when it has a bit depth the sequencer plays and
    no one is taking it; ``sequence`` when it is the next frame of a stored sequence (it does not
    replace a frame waiting for its trigger); ``showing``, its sequence entry's settings;
    ``low_plane``, the stored plane of its least significant plane."""
    valid: 1
    slot: SLOT_BITS
    depth: 4
    sequence: 1
    showing: Showing
    low_plane: 3


class FrameOffer(wiring.Component):
    """The store's offer, registered (``sync``).

    Members
    -------
    frames : In(stream.Signature(FrameInfo))
        The newest complete frame. A bit depth outside 1..8 is dropped when offered, and counted.
    answered : In(1)
        The frame offered is taken (answered now: ``ready``).
    offer : Out(Offer)
        The frame offered, as the store offered it the cycle before; not ``valid`` while a take
        is answered.
    held : Out(1)
        The frame offered is valid, takes answered now not counted in (registered).
    bad_frames : Out(COUNTER_BITS)
        Frames dropped for their bit depth.
    """

    frames: In(stream.Signature(FrameInfo))
    answered: In(1)
    offer: Out(Offer)
    held: Out(1)
    bad_frames: Out(COUNTER_BITS)

    def elaborate(self, platform):
        m = Module()
        frames, answered = self.frames, self.answered
        depth = frames.payload.bit_depth
        ok = (depth != 0) & (depth <= 8)
        held = Signal(Offer)
        m.d.sync += [held.valid.eq(frames.valid & ok & ~answered),
                     held.slot.eq(frames.payload.slot), held.depth.eq(depth),
                     held.sequence.eq(frames.payload.sequence),
                     held.showing.eq(frames.payload.showing), held.low_plane.eq(frames.payload.low_plane)]
        m.d.comb += [self.offer.eq(held), self.offer.valid.eq(held.valid & ~answered), self.held.eq(held.valid),
                     frames.ready.eq(answered | (frames.valid & ~ok))]
        m.submodules.bad = bad = Counter(COUNTER_BITS)
        bad_seen = Signal()                    # (counted a cycle later)
        m.d.sync += bad_seen.eq(frames.valid & ~ok)
        m.d.comb += [bad.inc.eq(bad_seen), self.bad_frames.eq(bad.count)]
        return m
