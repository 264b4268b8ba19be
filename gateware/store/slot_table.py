"""The slot table: the state of every frame slot, where a row goes, and the slot events.

It answers the row ingest's question "where does a row of frame f go?" with a :class:`Placement`
(the policy of :mod:`gateware.store.slots`, streaming or sequence mode), records the frames the
ingest opens and completes, and applies one housekeeping event per cycle: a change of mode
(only between rows), a slot written (from the writer), a release or an ask (from the sequencer,
in their order). The ingest only ever changes FREE and RECEIVING slots, housekeeping only the
others, so the two never change one slot on the same cycle.

A memory that lost its calibration (``lose``, :mod:`gateware.store.recovery`) holds every row
back and, between rows, makes the table forget every frame before any other event: each slot
not shown is freed, and each shown one is marked stale (its words are gone) so that it is freed,
not put back in a sequence, when the sequencer hands it back. Both are counted as frames lost.

Delta frames: a frame that carries only some rows names a whole frame as its base; its first row
is placed only if that base is held (being written, complete, shown or kept) and not stale, else
refused (``NO_BASE``). A slot that would be freed while a delta held uses it as its base is KEPT
instead (its words stay, it is never given out) and freed once no delta uses it.

A sequence with entries (``entries`` > 0) gives out the frame of each entry of the entry table
(:mod:`gateware.store.entries`) in turn instead of its slots in order, with the entry's settings;
an entry's slot may be shown already (the same frame twice in a row). An entry shows ``depth``
of its frame's planes below the ``skip`` most significant (depth 0: all below them; with skip 0
a depth beyond the frame's also means all): the answer gives that depth and the lowest stored
plane shown (the store keeps a frame of depth d in planes 8-d..7), worked out here, where the
frame's depth is known, so that the sequencer only adds a plane's exponent to it. Played once
(``loop`` low), the last entry's answer says so and no answer follows until ``sequence_start``
(or a change of mode) plays the entries from the first again. An entry that cannot be shown is
skipped and counted: its slot is outside the sequence, or its planes are not all in its frame
(skip + depth more than the frame's depth, or no plane left below the skipped ones).
"""

from dataclasses import dataclass

from amaranth import Array, Cat, Module, Mux, Signal
from amaranth.lib import data, enum, stream, wiring
from amaranth.lib.wiring import In, Out

from spec.records import ENTRIES

from .entries import ENTRY_BITS, Entry
from .layouts import COUNTER_BITS, LIVE_SLOTS, SLOT_BITS, FrameInfo
from .placement import Placement, PlacementSignature, opening_layout
from .slot_states import SlotStates

__all__ = ["SlotTable", "SlotState", "Placement", "PlacementSignature", "opening_layout", "TableCounters"]


class SlotState(enum.Enum, shape=3):
    FREE = 0
    RECEIVING = 1
    WRITING = 2
    READY = 3
    SHOWN = 4
    KEPT = 5          # no longer showable; its words stay while a delta frame uses them


class TableCounters(data.Struct):
    """The slot table's event counters (``COUNTER_BITS`` wide, wrapping); see
    :class:`~gateware.store.slots.SlotCounters`."""
    frames_replaced: COUNTER_BITS
    bad_releases: COUNTER_BITS
    calibration_losses: COUNTER_BITS
    frames_lost: COUNTER_BITS
    entries_skipped: COUNTER_BITS


class SlotTable(wiring.Component):
    """States of the frame slots, placement of rows, and housekeeping (``sync``).

    The first ``live`` slots are kept in registers and searched every cycle: streaming uses only
    those, and so do delta frames and their bases. A stored sequence spans every slot; the
    states of those beyond the live ones are in memory (:class:`~gateware.store.slot_states.SlotStates`),
    looked up by number, they hold whole frames only (a delta frame there is refused as having
    no base: ``NO_BASE``), and a change of mode or a lost memory walks them, one slot a cycle,
    while rows and asks wait.

    Parameters
    ----------
    slots : int
        Frame slots.
    frame_bits : int
        Width of the frame id.
    live : int
        Slots kept in registers (at most ``slots``).

    Members
    -------
    placement : In(PlacementSignature(frame_bits))
        The ingest's question and its answer.
    opened : In(stream.Signature(opening_layout(frame_bits), always_ready=True))
        The ingest has cleared a slot's maps for a new frame: the slot now receives it.
    completed : In(stream.Signature(SLOT_BITS, always_ready=True))
        Every row of the frame in this slot has arrived: it is being written.
    written : In(stream.Signature(SLOT_BITS))
        From the writer: the completing row of this slot is in memory.
    sequence_length : In(16)
        0: streaming; N: sequence of N frames in slots 0..N-1 (``slots`` at most: a longer one
        is cut to ``slots``).
    entries, loop, sequence_start : In(range(ENTRIES + 1)), In(1), In(1)
        A sequence's entries played (0: its slots in order); in a loop or once; a pulse that
        plays them from the first again.
    entry_index : Out(ENTRY_BITS); entry : In(Entry)
        The entry table's read port (block RAM, one cycle): the play position from the next cycle
        on, and the entry at the play position.
    asks : In(stream.Signature(0))
        Each transfer asks for one frame; an ask waits until a frame can be given.
    releases : In(stream.Signature(SLOT_BITS))
        Slots the sequencer hands back (taken before an ask waiting beside them).
    answers : Out(stream.Signature(FrameInfo))
        One answer per ask: the frame the sequencer now holds.
    lose : In(1)
        The memory's contents are lost: hold rows back, forget every frame once, answer no ask.
    forgotten : Out(1)
        Every frame has been forgotten since ``lose`` rose.
    counters : Out(TableCounters)
    """

    def __init__(self, *, slots=4, frame_bits=16, live=LIVE_SLOTS):
        assert slots <= 2**SLOT_BITS
        self._slots, self._frame_bits, self._live = slots, frame_bits, min(live, slots)
        super().__init__({
            "placement": In(PlacementSignature(frame_bits)),
            "opened": In(stream.Signature(opening_layout(frame_bits), always_ready=True)),
            "completed": In(stream.Signature(SLOT_BITS, always_ready=True)),
            "written": In(stream.Signature(SLOT_BITS)),
            "sequence_length": In(16),
            "entries": In(range(ENTRIES + 1)),
            "loop": In(1),
            "sequence_start": In(1),
            "entry_index": Out(ENTRY_BITS),
            "entry": In(Entry),
            "asks": In(stream.Signature(0)),
            "releases": In(stream.Signature(SLOT_BITS)),
            "answers": Out(stream.Signature(FrameInfo)),
            "lose": In(1),
            "forgotten": Out(1),
            "counters": Out(TableCounters),
        })

    def elaborate(self, platform):
        m = Module()
        n_slots, live = self._slots, self._live
        count = self.counters
        t = _Registers(live, self._frame_bits)
        slots = _Slots(m, t, n_slots, live)
        state, in_sequence, stale = t.state, t.in_sequence, t.stale

        # -- mode
        seq_len = Signal(range(n_slots + 1))          # the mode in force
        wanted_len = Signal(range(n_slots + 1))
        m.d.comb += wanted_len.eq(Mux(self.sequence_length > n_slots, n_slots, self.sequence_length))
        mode_pending = Signal()
        sequence = Signal()
        m.d.comb += [mode_pending.eq(wanted_len != seq_len), sequence.eq(seq_len != 0)]
        # the sequence slots' walk (a change of mode, a lost memory): their states are in memory
        walking, walk_loss = Signal(), Signal()
        walk_slot = Signal(SLOT_BITS)
        high_ready = Signal(range(n_slots + 1))     # sequence slots beyond the live ones complete

        self._place(m, slots, seq_len, mode_pending | walking, sequence)

        self._ingest_events(m, slots, sequence)

        # -- the answer to an ask
        answer = self._answer(m, slots, seq_len, sequence, high_ready)
        play, finished, advance = answer.play, answer.finished, answer.advance
        answer_slot, can_answer, skip = answer.slot, answer.can_answer, answer.skip

        # -- a base no delta uses any more is freed (housekeeping below never changes a KEPT slot
        # but to FREE)
        used = self._free_unused_bases(m, t)

        def retired(s):
            """What slot ``s`` becomes once neither shown nor showable: kept while a delta uses it
            (a live slot), else free."""
            return Mux((s < live) & used[s], SlotState.KEPT, SlotState.FREE)

        # -- housekeeping: one event per cycle. An answer offered and not taken (the answer FIFO
        # full) stays offered, unchanged: nothing else happens until it is taken.
        offered = Signal()
        m.d.sync += offered.eq(self.answers.valid & ~self.answers.ready)
        released = self.releases.payload
        done = self.written.payload
        # the slot housekeeping looks at (the event below that takes it)
        hk = slots.housekeeping(Mux(walking, walk_slot,
                                    Mux(self.written.valid & ~offered, done,
                                        Mux(self.releases.valid & ~offered, released, answer_slot))))
        with m.If(~self.lose):
            m.d.sync += self.forgotten.eq(0)
        with m.If(walking):
            self._walk_step(m, slots, hk, walking, walk_loss, walk_slot)
        with m.Elif(self.lose & ~self.forgotten & self.placement.between_rows & ~offered):
            m.d.sync += [t.recv_active.eq(0), t.last_valid.eq(0), high_ready.eq(0),
                         count.calibration_losses.eq(count.calibration_losses + 1),
                         count.frames_lost.eq(count.frames_lost
                                              + sum(state[s] != SlotState.FREE for s in range(live)))]
            self._walk(m, walking, walk_loss, walk_slot, loss=True)
            for s in range(live):
                with m.If(state[s] == SlotState.SHOWN):
                    m.d.sync += stale[s].eq(1)
                with m.Else():
                    m.d.sync += state[s].eq(SlotState.FREE)
        with m.Elif(mode_pending & self.placement.between_rows & ~offered):
            m.d.comb += play.next.eq(0)
            m.d.sync += [seq_len.eq(wanted_len), finished.eq(0), t.recv_active.eq(0),
                         t.last_valid.eq(0), high_ready.eq(0)]
            self._walk(m, walking, walk_loss, walk_slot, loss=False)
            for s in range(live):
                with m.If(state[s] != SlotState.SHOWN):
                    m.d.sync += state[s].eq(retired(s))
                m.d.sync += in_sequence[s].eq(0)
        with m.Elif(self.written.valid & ~offered):
            m.d.comb += self.written.ready.eq(1)
            with m.If(hk.state == SlotState.WRITING):
                slots.keep(state=SlotState.READY)
                with m.If(done >= live):
                    m.d.sync += high_ready.eq(high_ready + 1)
                with m.Else():
                    # streaming: the newest complete frame replaces one never shown
                    for s in range(live):
                        with m.If((state[s] == SlotState.READY) & ~in_sequence[s] & ~in_sequence[done]
                                  & (done != s)):
                            m.d.sync += [state[s].eq(retired(s)),
                                         count.frames_replaced.eq(count.frames_replaced + 1)]
        with m.Elif(self.releases.valid & ~offered):
            m.d.comb += self.releases.ready.eq(1)
            with m.If(hk.state != SlotState.SHOWN):
                slots.keep(stale=0)
                m.d.sync += count.bad_releases.eq(count.bad_releases + 1)
            with m.Elif(hk.in_sequence & sequence & ~hk.stale):
                slots.keep(state=SlotState.READY, stale=0)
            with m.Elif(hk.stale):
                slots.keep(state=SlotState.FREE, stale=0)
            with m.Else():
                slots.keep(state=retired(released), stale=0)
        with m.Elif(self.asks.valid & can_answer & ~self.lose):
            m.d.comb += self.answers.valid.eq(1)
            with m.If(self.answers.ready):
                m.d.comb += self.asks.ready.eq(1)
                slots.keep(state=SlotState.SHOWN)
                with m.If(sequence):
                    advance()
        with m.Elif(skip & ~offered & ~self.lose):
            advance()
            m.d.sync += count.entries_skipped.eq(count.entries_skipped + 1)
        # last: from the first entry again (over an answer given out this cycle)
        with m.If(self.sequence_start):
            m.d.comb += play.next.eq(0)
            m.d.sync += finished.eq(0)
        return m

    def _ingest_events(self, m, slots, sequence):
        """The ingest's news: a slot opened for a frame (it receives it from now on) and a slot
        whose rows have all arrived (it is being written)."""
        registers, opening = slots.t, self.opened.payload
        with m.If(self.opened.valid):
            slots.ingest(opening.slot, SlotState.RECEIVING, in_sequence=sequence, depth=opening.depth)
            with m.If(opening.slot < self._live):
                m.d.sync += [
                    registers.frame_id[opening.slot].eq(opening.frame),
                    registers.delta[opening.slot].eq(opening.delta),
                    registers.base[opening.slot].eq(opening.base),
                ]
            with m.If(~sequence):
                m.d.sync += [registers.recv_active.eq(1), registers.recv_slot.eq(opening.slot),
                             registers.recv_frame.eq(opening.frame), registers.last_valid.eq(1),
                             registers.last_frame.eq(opening.frame)]
        with m.If(self.completed.valid):
            slots.ingest(self.completed.payload, SlotState.WRITING)
            with m.If(~sequence):
                m.d.sync += registers.recv_active.eq(0)

    def _free_unused_bases(self, m, registers):
        """Free each KEPT slot that no delta uses as its base any more. Returns, per live slot,
        whether a delta held uses it (an :class:`Array`)."""
        live, state = self._live, registers.state
        used = [Signal(name=f"used{slot}") for slot in range(live)]
        for slot in range(live):
            m.d.comb += used[slot].eq(Cat((state[other] != SlotState.FREE) & registers.delta[other]
                                          & (registers.base[other] == slot) & ~registers.stale[other]
                                          for other in range(live) if other != slot).any())
            with m.If((state[slot] == SlotState.KEPT) & ~used[slot]):
                m.d.sync += state[slot].eq(SlotState.FREE)
        return Array(used)

    def _walk_step(self, m, slots, looked_at, walking, walk_loss, walk_slot):
        """One sequence slot a cycle (``looked_at``, housekeeping's view of ``walk_slot``): a loss
        forgets it (stale if shown), a change of mode frees it unless shown and takes it out of
        the sequence."""
        count = self.counters
        with m.If(walk_loss):
            with m.If(looked_at.state != SlotState.FREE):
                m.d.sync += count.frames_lost.eq(count.frames_lost + 1)
            with m.If(looked_at.state == SlotState.SHOWN):
                slots.keep(stale=1)
            with m.Else():
                slots.keep(state=SlotState.FREE)
        with m.Else():
            slots.keep(state=Mux(looked_at.state == SlotState.SHOWN, SlotState.SHOWN, SlotState.FREE), in_sequence=0)
        m.d.sync += walk_slot.eq(walk_slot + 1)
        with m.If(walk_slot == self._slots - 1):
            m.d.sync += walking.eq(0)
            with m.If(walk_loss):
                m.d.sync += self.forgotten.eq(self.lose)

    def _walk(self, m, walking, walk_loss, walk_slot, *, loss):
        """Start the walk over the sequence slots (if there are any beyond the live ones);
        without them a loss is forgotten at once."""
        if self._slots > self._live:
            m.d.sync += [walking.eq(1), walk_loss.eq(loss), walk_slot.eq(self._live)]
        elif loss:
            m.d.sync += self.forgotten.eq(1)

    def _answer(self, m, slots, seq_len, sequence, high_ready):
        """Drive ``answers``: which frame an ask is given (streaming: the newest ready; a
        sequence: its slots in order, or its table's entries with their settings), and the
        play position's registers. Returns them with ``advance()`` (the play position after a
        frame given out or skipped)."""
        live = self._live
        t = slots.t
        state, in_sequence = t.state, t.in_sequence
        ready_found, ready_slot = _first_of(m, live, lambda s: (state[s] == SlotState.READY) & ~in_sequence[s])
        # the slot, or the entry, given out next; the entry table is read a cycle ahead, at the
        # position from the next cycle on (``play.next``)
        play = Position(now=Signal(ENTRY_BITS, name="play"), next=Signal(ENTRY_BITS, name="play_next"))
        m.d.comb += play.next.eq(play.now)
        m.d.sync += play.now.eq(play.next)
        finished = Signal()            # played once: the last entry given out
        # every slot of the sequence holds its frame (those beyond the live ones counted as they
        # complete: they never go back but through a walk, which restarts the count)
        loaded = Signal()
        m.d.comb += loaded.eq(high_ready + live >= seq_len)
        for s in range(live):
            with m.If((s < seq_len) & ~((state[s] == SlotState.READY) | (state[s] == SlotState.SHOWN))):
                m.d.comb += loaded.eq(0)
        entry = self.entry
        by_entry = sequence & (self.entries != 0)
        last_entry = play.now + 1 >= self.entries
        answer_slot = Signal(SLOT_BITS)
        with m.If(by_entry):
            m.d.comb += answer_slot.eq(entry.slot)
        with m.Elif(sequence):
            m.d.comb += answer_slot.eq(play.now)
        with m.Else():
            m.d.comb += answer_slot.eq(ready_slot)
        given = slots.view("answer", answer_slot)
        shown_depth, low_plane, missing = _entry_planes(m, entry, given.depth)
        # (a frame's depth is known once every slot of the sequence holds its frame)
        skip = by_entry & ~finished & ((entry.slot >= seq_len) | (loaded & missing))
        m.d.comb += self.entry_index.eq(play.next)
        can_answer = Signal()
        with m.If(by_entry):
            # (an entry may show the frame shown now: the sequencer holds a slot once)
            m.d.comb += can_answer.eq(loaded & ~finished & ~skip & ((given.state == SlotState.READY)
                                                                | (given.state == SlotState.SHOWN)))
        with m.Elif(sequence):
            m.d.comb += can_answer.eq(loaded & (given.state == SlotState.READY))
        with m.Else():
            m.d.comb += can_answer.eq(ready_found)
        answer = self.answers.payload
        m.d.comb += [
            answer.slot.eq(answer_slot),
            answer.frame_id.eq(given.frame_id),
            answer.bit_depth.eq(given.depth),
            answer.low_plane.eq(8 - given.depth),
            answer.sequence.eq(sequence),
        ]
        with m.If(by_entry):
            m.d.comb += [answer.bit_depth.eq(shown_depth), answer.low_plane.eq(low_plane),
                         answer.showing.lsb.eq(entry.lsb), answer.showing.dark.eq(entry.dark),
                         answer.showing.follow.eq(entry.follow), answer.showing.camera_off.eq(entry.camera_off),
                         answer.showing.last.eq(~self.loop & last_entry)]

        def advance():
            """The play position after the entry (or slot) given out or skipped."""
            with m.If(by_entry):
                m.d.comb += play.next.eq(Mux(last_entry, 0, play.now + 1))
                with m.If(last_entry & ~self.loop):
                    m.d.sync += finished.eq(1)
            with m.Else():
                m.d.comb += play.next.eq(Mux(play.now + 1 >= seq_len, 0, play.now + 1))
        return Answering(play=play, finished=finished, advance=advance, slot=answer_slot,
                         can_answer=can_answer, skip=skip)

    def _place(self, m, slots, seq_len, hold, sequence):
        """Drive ``placement``: where a row of ``placement.frame`` goes, from the registers ``t``
        (and, for a sequence, the sequence slots' states)."""
        place = self.placement
        live, frame_bits = self._live, self._frame_bits
        t = slots.t
        state = t.state
        free_found, free_slot = _first_of(m, live, lambda s: state[s] == SlotState.FREE)
        writing_found, _ = _first_of(m, live, lambda s: state[s] == SlotState.WRITING)
        shown_match, _ = _first_of(m, live,
                                   lambda s: (state[s] == SlotState.SHOWN) & (t.frame_id[s] == place.frame))
        base_found, base_slot = _first_of(
            m, live, lambda s: ((state[s] == SlotState.WRITING) | (state[s] == SlotState.READY)
                                | (state[s] == SlotState.SHOWN) | (state[s] == SlotState.KEPT))
            & ~t.delta[s] & ~t.stale[s] & (t.frame_id[s] == place.base))
        no_base = place.delta & ~base_found
        m.d.comb += [place.base_slot.eq(base_slot), place.base_depth.eq(t.depth[base_slot])]
        newer = Signal()
        diff = Signal(frame_bits)
        m.d.comb += [diff.eq(place.frame - t.last_frame), newer.eq((diff != 0) & ~diff[frame_bits - 1])]

        def verdict(value, slot=None):
            m.d.comb += place.verdict.eq(value)
            if slot is not None:
                m.d.comb += place.slot.eq(slot)

        seq_slot = place.frame[:SLOT_BITS]
        seq = slots.view("place", seq_slot)
        # (a sequence's row joins its frame's slot: the one looked up)
        m.d.comb += place.depth.eq(Mux(sequence, seq.depth, t.depth[place.slot]))
        with m.If(hold | self.lose):
            verdict(Placement.HOLD)
        with m.Elif(sequence):
            with m.If(place.frame >= seq_len):
                verdict(Placement.STALE)
            with m.Elif((seq.state == SlotState.FREE) & (no_base | place.delta & (seq_slot >= live))):
                verdict(Placement.NO_BASE)
            with m.Elif(seq.state == SlotState.FREE):
                verdict(Placement.TAKE, seq_slot)
            with m.Elif(seq.state == SlotState.RECEIVING):
                verdict(Placement.JOIN, seq_slot)
            with m.Elif(seq.state == SlotState.SHOWN):
                verdict(Placement.SHOWN)
            with m.Else():
                verdict(Placement.DUPLICATE)
        with m.Elif(t.recv_active & (place.frame == t.recv_frame)):
            verdict(Placement.JOIN, t.recv_slot)
        with m.Elif(~t.last_valid | newer):
            with m.If(no_base):
                verdict(Placement.NO_BASE)
            with m.Elif(t.recv_active):
                verdict(Placement.ABANDON, t.recv_slot)
            with m.Elif(free_found):
                verdict(Placement.TAKE, free_slot)
            with m.Elif(~writing_found):
                verdict(Placement.NO_SLOT)
            with m.Else():
                verdict(Placement.WAIT)
        with m.Elif(shown_match):
            verdict(Placement.SHOWN)
        with m.Else():
            verdict(Placement.STALE)


@dataclass(frozen=True)
class Position:
    """The sequence entry given out: ``now`` (registered) and ``next`` (from the next cycle on)."""
    now: Signal
    next: Signal


@dataclass(frozen=True)
class Answering:
    """What the table answers the sequencer with this cycle: the slot, whether it can answer,
    whether the entry is skipped, and the sequence's play position and end."""
    play: Position
    finished: Signal
    advance: Signal
    slot: Signal
    can_answer: Signal
    skip: Signal


@dataclass(frozen=True)
class SlotFields:
    """A slot's fields read this cycle (from registers, or from LUT RAM beyond the live slots)."""
    state: object
    depth: object
    in_sequence: object
    stale: object
    frame_id: object


class _Slots:
    """Every slot's fields, looked up by slot number: the live slots' registers ``t``, and the
    sequence slots' states in memory (:class:`~gateware.store.slot_states.SlotStates`) when there
    are slots beyond the live ones. Each view is one of the memory's read ports."""

    def __init__(self, m, t, slots, live):
        self.m, self.t, self.live = m, t, live
        self.memory = None
        if slots > live:
            m.submodules.sequence_slots = self.memory = SlotStates(slots, views=("place", "answer"))
        self._hk_slot = None

    def view(self, name, slot):
        """The fields of slot ``slot`` (a value), this cycle."""
        t, live = self.t, self.live
        fields = SlotFields(state=t.state[slot], depth=t.depth[slot], in_sequence=t.in_sequence[slot],
                            stale=t.stale[slot], frame_id=t.frame_id[slot])
        if self.memory is None:
            return fields
        port = getattr(self.memory, name)
        self.m.d.comb += port.slot.eq(slot)
        low = slot < live
        return SlotFields(state=Mux(low, fields.state, port.state), depth=Mux(low, fields.depth, port.depth),
                          in_sequence=Mux(low, fields.in_sequence, port.in_sequence),
                          stale=Mux(low, fields.stale, port.stale),
                          frame_id=Mux(low, fields.frame_id, slot))

    def housekeeping(self, slot):
        """The view of the slot housekeeping changes (with :meth:`keep`)."""
        self._hk_slot = slot
        self._hk = self.view("housekeeping", slot)
        return self._hk

    def keep(self, *, state=None, in_sequence=None, stale=None):
        """Housekeeping changes its slot's fields (those given) on this clock edge."""
        m, t, slot, hk = self.m, self.t, self._hk_slot, self._hk
        with m.If(slot < self.live):
            for regs, value in ((t.state, state), (t.in_sequence, in_sequence), (t.stale, stale)):
                if value is not None:
                    m.d.sync += regs[slot].eq(value)
        if self.memory is not None:
            with m.Else():
                w = self.memory.housekeeping_write
                m.d.comb += [w.en.eq(1), w.phase.state.eq(hk.state if state is None else state),
                             w.phase.in_sequence.eq(hk.in_sequence if in_sequence is None else in_sequence),
                             w.stale.eq(hk.stale if stale is None else stale)]

    def ingest(self, slot, state, *, in_sequence=None, depth=None):
        """The ingest changes slot ``slot``: it becomes ``state`` (and ``in_sequence``, and its
        bit depth ``depth``) on this clock edge."""
        m, t = self.m, self.t
        with m.If(slot < self.live):
            m.d.sync += t.state[slot].eq(state)
            if in_sequence is not None:
                m.d.sync += t.in_sequence[slot].eq(in_sequence)
            if depth is not None:
                m.d.sync += t.depth[slot].eq(depth)
        if self.memory is not None:
            with m.Else():
                w = self.memory.ingest_write
                m.d.comb += [w.en.eq(1), w.slot.eq(slot), w.phase.state.eq(state)]
                if in_sequence is not None:
                    m.d.comb += w.phase.in_sequence.eq(in_sequence)
                else:
                    # (completing a slot keeps it in the sequence it was opened in)
                    m.d.comb += w.phase.in_sequence.eq(1)
                if depth is not None:
                    m.d.comb += [w.depth.eq(depth), w.depth_en.eq(1)]


class _Registers:
    """The table's registers: per slot, and in streaming mode the frame receiving and the newest
    frame started."""

    def __init__(self, slots, frame_bits):
        self.state = Array(Signal(SlotState, name=f"state{s}") for s in range(slots))
        self.frame_id = Array(Signal(frame_bits, name=f"frame_id{s}") for s in range(slots))
        self.depth = Array(Signal(4, name=f"depth{s}") for s in range(slots))
        self.in_sequence = Array(Signal(name=f"in_sequence{s}") for s in range(slots))
        self.stale = Array(Signal(name=f"stale{s}") for s in range(slots))
        self.delta = Array(Signal(name=f"delta{s}") for s in range(slots))
        self.base = Array(Signal(SLOT_BITS, name=f"base{s}") for s in range(slots))
        self.recv_active = Signal()
        self.recv_slot = Signal(SLOT_BITS)
        self.recv_frame = Signal(frame_bits)
        self.last_valid = Signal()
        self.last_frame = Signal(frame_bits)


def _entry_planes(m, entry, frame_depth):
    """The planes ``entry`` shows of a frame of ``frame_depth`` planes (stored in planes
    ``8 - frame_depth .. 7``): (its depth, its lowest stored plane, its planes are not all in the
    frame)."""
    shown, low, missing = Signal(4), Signal(3), Signal()
    # all the frame has below the skipped planes (skip 0: a depth beyond the frame's too, as
    # entries without a skip always meant it)
    whole = (entry.depth == 0) | ((entry.skip == 0) & (entry.depth >= frame_depth))
    with m.If(whole):
        m.d.comb += [shown.eq(frame_depth - entry.skip), low.eq(8 - frame_depth),
                     missing.eq(entry.skip >= frame_depth)]
    with m.Else():
        m.d.comb += [shown.eq(entry.depth), low.eq(entry.low_plane), missing.eq(entry.need > frame_depth)]
    return shown, low, missing


def _first_of(m, slots, condition):
    """(any, index of the lowest slot ``s`` < ``slots`` with ``condition(s)``), driven in ``m``."""
    found, index = Signal(), Signal(SLOT_BITS)
    for s in reversed(range(slots)):
        with m.If(condition(s)):
            m.d.comb += [found.eq(1), index.eq(s)]
    return found, index
