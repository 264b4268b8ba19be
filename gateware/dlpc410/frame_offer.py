"""The frame the store offers, as the sequencer's decisions read it: registered.

The store offers its newest complete frame on a stream. Its offer is registered (the decisions
that read it start from flip-flops, :data:`spec.schedule.OFFER_LAG`), and free to take unless a
take is being answered; a frame taken is answered while the store still offers it (a stream
holds its payload until the transfer), and one with a bit depth the sequencer does not play is
dropped the cycle after it is offered, and counted: outside 1..8, or one the plane order in force
cannot show (with an order table, the first ``depth`` entries of every table in force must name
the frame's planes, exponents 0..depth-1, or the frame would show planes beyond its own).

Which depths the order shows is worked out from the registers in two registered steps (each
table's prefixes, then the tables in force): for two cycles after the registers change (and
after reset) the offer waits, neither offered nor dropped.
"""

from amaranth import Cat, Module, Mux, Signal
from amaranth.lib import data, stream, wiring
from amaranth.lib.wiring import In, Out

from spec.registers import MAX_GROUPS

from ..counter import Counter
from ..registers import PlaneOrder, Registers
from ..store.layouts import SLOT_BITS, FrameInfo, Showing
from .layouts import COUNTER_BITS
from .timebase import group_tables

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

    Parameters
    ----------
    groups : int
        Pulse groups at most (the DMD's blocks).

    Members
    -------
    regs : In(:class:`~gateware.registers.Registers`)
    active : In(groups)
        Bit g: group g is one of the reset mode's (registered from ``regs``).
    reload : In(1)
        The registers change in this cycle.
    frames : In(stream.Signature(FrameInfo))
        The newest complete frame. A bit depth outside 1..8, or one the plane order cannot show,
        is dropped when offered, and counted.
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

    def __init__(self, groups):
        self._groups = groups
        super().__init__({
            "regs": In(Registers),
            "active": In(groups),
            "reload": In(1),
            "frames": In(stream.Signature(FrameInfo)),
            "answered": In(1),
            "offer": Out(Offer),
            "held": Out(1),
            "bad_frames": Out(COUNTER_BITS),
        })

    def _shown_depths(self, m):
        """Bit d-1 high when the order in force shows frames of d planes (registered twice), and
        whether those bits follow the registers in force yet."""
        regs, groups = self.regs, min(self._groups, MAX_GROUPS)
        tables = group_tables(regs, groups)

        def prefixes(table, name):
            # bit d-1: the first d entries are all below d (a permutation's prefix names 0..d-1)
            ok = Signal(8, name=name)
            m.d.sync += ok.eq(Cat(Cat(table[3 * j:3 * j + 3] < d for j in range(d)).all()
                                  for d in range(1, 9)))
            return ok

        own = prefixes(regs.order_table.as_value(), "table_depths")
        each = [prefixes(tables[g], f"group{g}_depths") for g in range(groups)]
        shown = Signal(8)
        with m.Switch(regs.order):
            with m.Case(PlaneOrder.TABLE):
                m.d.sync += shown.eq(own)
            with m.Case(PlaneOrder.GROUPS):
                m.d.sync += shown.eq(Cat(Cat(~self.active[g] | each[g][d] for g in range(groups)).all()
                                         for d in range(8)))
            with m.Default():
                m.d.sync += shown.eq(0xFF)
        stale = Signal(range(3), init=2)       # cycles until ``shown`` follows the registers
        m.d.sync += stale.eq(Mux(self.reload, 1, Mux(stale != 0, stale - 1, 0)))
        return shown, ~self.reload & (stale == 0)

    def elaborate(self, platform):
        m = Module()
        frames, answered = self.frames, self.answered
        depth = frames.payload.bit_depth
        shown, known = self._shown_depths(m)
        ok = (depth != 0) & (depth <= 8) & Cat(0, shown).bit_select(depth, 1)
        # the frame and its verdict, registered: offered if its depth is shown, dropped the
        # cycle after if not (the store holds it until then: ``held.valid``, it was not taken),
        # neither while ``shown`` is stale
        held, shows, bad = Signal(Offer), Signal(), Signal()
        m.d.sync += [held.valid.eq(frames.valid & ~frames.ready), shows.eq(known & ok), bad.eq(known & ~ok),
                     held.slot.eq(frames.payload.slot), held.depth.eq(depth),
                     held.sequence.eq(frames.payload.sequence),
                     held.showing.eq(frames.payload.showing), held.low_plane.eq(frames.payload.low_plane)]
        offered = held.valid & shows
        dropped = frames.valid & held.valid & bad
        m.d.comb += [self.offer.eq(held), self.offer.valid.eq(offered & ~answered), self.held.eq(offered),
                     frames.ready.eq(answered | dropped)]
        m.submodules.bad = bad_count = Counter(COUNTER_BITS)
        m.d.comb += [bad_count.inc.eq(dropped), self.bad_frames.eq(bad_count.count)]
        return m
