"""Frame slots: which frame goes where in DDR2, when it may be shown, and the occupancy map.

The slot keeper sits between the serialiser and the writer (``sync`` domain). For every row it
decides, at the row's first word, whether the row is stored and in which slot; a refused row is
dropped whole and counted, an accepted one goes to the writer with its slot, so a row can only
ever be written inside the slot chosen here, whatever its header said.

Slot life
---------
``FREE -> RECEIVING -> WRITING -> READY -> SHOWN -> FREE`` (streaming) or ``-> READY`` again
(sequence). A slot is RECEIVING while rows arrive (a row bitmap says which), WRITING once every
row has arrived until the writer reports the last row in memory, READY (complete) until the
sequencer is given it, SHOWN until the sequencer releases it. Only RECEIVING slots are written,
so a READY or SHOWN frame never changes (no tearing).

Streaming mode (``sequence_length`` = 0): one frame receives at a time. A row of a frame id
newer (serial-number order) than the last one started begins a new frame; a receiving frame it
interrupts is abandoned (counted: it was never complete, so never shown). When a frame
completes, an older READY one that was never shown is freed (counted as replaced). A row of an
older frame is refused (counted: stale, or shown if that frame is being shown). At least three
slots: one receiving, one ready, one shown.

Sequence mode (``sequence_length`` = N > 0): frame id f < N goes to slot f; once all N are
complete they are given to the sequencer in order 0, 1, .., N-1, 0, .. and a released slot stays
in the sequence. Changing ``sequence_length`` frees every slot that is not shown.

Occupancy
---------
Per slot and DMD block, 8 bits: plane k has a bit set somewhere in the block (the OR of the
serialiser's row flags). Cleared when a slot is taken for a new frame, written only while the
slot receives; read from the ``dmd`` domain through a second read port of the same memory,
which is safe because a slot reaches the sequencer only after it is complete (see
:mod:`gateware.store.layouts`).
"""

from amaranth import Array, Cat, Const, Module, Signal
from amaranth.lib import data, enum, stream, wiring
from amaranth.lib.fifo import AsyncFIFO
from amaranth.lib.memory import Memory
from amaranth.lib.wiring import In, Out
from amaranth.utils import ceil_log2

from gateware.bitplane.serialiser import row_flags_layout, word_layout

from .addresses import PLANES
from .layouts import BLOCK_BITS, SLOT_BITS, FrameInfo, OccupancySignature
from .writer import write_word_layout

__all__ = ["FrameSlots", "SlotState", "SlotCounters"]


class SlotState(enum.Enum, shape=3):
    FREE = 0
    RECEIVING = 1
    WRITING = 2
    READY = 3
    SHOWN = 4


class SlotCounters(data.Struct):
    """Event counters (16 bits, wrapping)."""
    frames_complete: 16     # every row arrived
    frames_replaced: 16     # complete, freed unshown for a newer one (streaming)
    frames_abandoned: 16    # receiving, interrupted by a newer frame before it was complete
    rows_outside: 16        # row number beyond the frame: refused
    rows_stale: 16          # frame id older than the frame receiving, or not in the sequence
    rows_shown: 16          # frame id of a slot being shown: refused
    rows_duplicate: 16      # row already received (overlapping records): refused
    rows_no_slot: 16        # no slot free (the sequencer holds too many): refused
    bad_releases: 16        # release of a slot that was not shown


class _Command(data.Struct):
    """dmd -> sync: an ask, or the release of a slot."""
    release: 1
    slot: SLOT_BITS


class FrameSlots(wiring.Component):
    """Frame slots, row bookkeeping and the occupancy map of the store.

    Parameters
    ----------
    dmd : :class:`spec.facts.DmdType`
    slots : int
        Frame slots (3 to 16).
    frame_bits : int
        Width of the serialiser's frame tag: the frame id of the record (up to 16 bits).

    Members
    -------
    words : In(stream.Signature(serialiser.word_layout(dmd, frame_bits)))
        The serialiser's words (``sync``).
    rows : In(stream.Signature(serialiser.row_flags_layout(dmd, frame_bits)))
        The serialiser's row flags (``sync``); taken together with the last word of each row.
    store : Out(stream.Signature(writer.write_word_layout(dmd)))
        Accepted words of the stored planes, to the writer (``sync``).
    written : In(stream.Signature(SLOT_BITS))
        From the writer: the completing row of this slot is in memory (``sync``).
    bit_depth : In(4)
        Planes to store for frames that start from now on, 1..8 (others mean 8) (``sync``).
    sequence_length : In(5)
        0: streaming; N: sequence of N frames in slots 0..N-1 (at most ``slots``) (``sync``).
    counters : Out(SlotCounters)
        (``sync``).
    ask : In(stream.Signature(0))
        Each transfer asks for one frame to show (``dmd``).
    frames : Out(stream.Signature(FrameInfo))
        The answers: frames the sequencer now holds (``dmd``).
    release : In(stream.Signature(SLOT_BITS))
        Slots the sequencer hands back (``dmd``).
    occupancy : In(OccupancySignature())
        Occupancy map read port (``dmd``).
    """

    def __init__(self, dmd, *, slots=4, frame_bits=16):
        assert 3 <= slots <= 2**SLOT_BITS and dmd.blocks <= 2**BLOCK_BITS and frame_bits <= 16
        assert dmd.rows >= 2**BLOCK_BITS
        self._dmd, self._slots, self._frame_bits = dmd, slots, frame_bits
        super().__init__({
            "words": In(stream.Signature(word_layout(dmd, frame_bits))),
            "rows": In(stream.Signature(row_flags_layout(dmd, frame_bits))),
            "store": Out(stream.Signature(write_word_layout(dmd))),
            "written": In(stream.Signature(SLOT_BITS)),
            "bit_depth": In(4),
            "sequence_length": In(5),
            "counters": Out(SlotCounters),
            "ask": In(stream.Signature(0)),
            "frames": Out(stream.Signature(FrameInfo)),
            "release": In(stream.Signature(SLOT_BITS)),
            "occupancy": In(OccupancySignature()),
        })

    def elaborate(self, platform):
        m = Module()
        dmd, n_slots, fb = self._dmd, self._slots, self._frame_bits
        wpr, row_bits = dmd.words_per_row, ceil_log2(dmd.rows)
        count = self.counters

        # -- per-slot state
        state = Array(Signal(SlotState, name=f"state{s}") for s in range(n_slots))
        frame_id = Array(Signal(fb, name=f"frame_id{s}") for s in range(n_slots))
        depth = Array(Signal(4, name=f"depth{s}") for s in range(n_slots))
        received = Array(Signal(range(dmd.rows + 1), name=f"received{s}") for s in range(n_slots))
        in_sequence = Array(Signal(name=f"in_sequence{s}") for s in range(n_slots))

        # -- streaming: the frame receiving and the newest frame started
        recv_active = Signal()
        recv_slot = Signal(SLOT_BITS)
        recv_frame = Signal(fb)
        last_valid = Signal()
        last_frame = Signal(fb)

        # -- mode
        seq_len = Signal(5)          # the mode in force
        wanted_len = Signal(5)
        m.d.comb += wanted_len.eq(self.sequence_length)
        with m.If(self.sequence_length > n_slots):
            m.d.comb += wanted_len.eq(n_slots)
        mode_pending = Signal()
        m.d.comb += mode_pending.eq(wanted_len != seq_len)
        sequence = Signal()
        m.d.comb += sequence.eq(seq_len != 0)
        depth_in = Signal(4)
        m.d.comb += depth_in.eq(self.bit_depth)
        with m.If((self.bit_depth == 0) | (self.bit_depth > PLANES)):
            m.d.comb += depth_in.eq(PLANES)

        # -- memories: row bitmap (sync only) and occupancy map (written in sync, read in dmd)
        m.submodules.bitmap = bitmap = Memory(shape=1, depth=n_slots << row_bits, init=[])
        bitmap_w = bitmap.write_port()
        bitmap_r = bitmap.read_port()
        m.submodules.occupancy = occ = Memory(shape=PLANES, depth=n_slots << BLOCK_BITS, init=[])
        occ_w = occ.write_port(granularity=1)
        occ_r = occ.read_port(domain="dmd")
        m.d.comb += [
            occ_r.addr.eq(Cat(self.occupancy.block, self.occupancy.slot)),
            self.occupancy.planes.eq(occ_r.data),
        ]

        head = self.words.payload
        flags = self.rows.payload
        is_last = (head.plane == PLANES - 1) & (head.word == wpr - 1)
        cur_slot = Signal(SLOT_BITS)
        cur_depth = Signal(4)
        clear_index = Signal(row_bits)

        m.d.comb += bitmap_r.addr.eq(Cat(head.row, cur_slot))
        stored_mask = Signal(PLANES)            # planes a frame of depth cur_depth stores
        m.d.comb += stored_mask.eq(Const(0xFF00, 2 * PLANES) >> cur_depth)

        def first_of(condition):
            """(any, index of the lowest slot with condition(s))."""
            found, index = Signal(), Signal(SLOT_BITS)
            for s in reversed(range(n_slots)):
                with m.If(condition(s)):
                    m.d.comb += [found.eq(1), index.eq(s)]
            return found, index

        free_found, free_slot = first_of(lambda s: state[s] == SlotState.FREE)
        writing_found, _ = first_of(lambda s: state[s] == SlotState.WRITING)
        shown_match, _ = first_of(lambda s: (state[s] == SlotState.SHOWN) & (frame_id[s] == head.frame))
        newer = Signal()
        diff = Signal(fb)
        m.d.comb += [diff.eq(head.frame - last_frame), newer.eq((diff != 0) & ~diff[fb - 1])]

        def take(slot, *, abandon=False):
            m.d.sync += [cur_slot.eq(slot), clear_index.eq(0)]
            if abandon:
                m.d.sync += count.frames_abandoned.eq(count.frames_abandoned + 1)
            m.next = "CLEAR"

        def refuse(counter):
            m.d.sync += counter.eq(counter + 1)
            m.next = "DROP"

        # the store payload follows the head word
        m.d.comb += [
            self.store.payload.data.eq(head.data),
            self.store.payload.slot.eq(cur_slot),
            self.store.payload.plane.eq(head.plane),
            self.store.payload.row.eq(head.row),
            self.store.payload.word.eq(head.word),
            self.store.payload.last.eq(is_last),
            self.store.payload.completes.eq(received[cur_slot] == dmd.rows - 1),
        ]

        with m.FSM(name="ingest") as ingest:
            with m.State("ROW_START"):
                # a change of mode is applied first, between rows (housekeeping, below)
                with m.If(self.words.valid & ~mode_pending):
                    seq_slot = head.frame[:SLOT_BITS]
                    with m.If(head.row >= dmd.rows):
                        refuse(count.rows_outside)
                    with m.Elif(sequence):
                        with m.If(head.frame >= seq_len):
                            refuse(count.rows_stale)
                        with m.Elif(state[seq_slot] == SlotState.FREE):
                            take(seq_slot)
                        with m.Elif(state[seq_slot] == SlotState.RECEIVING):
                            m.d.sync += [cur_slot.eq(seq_slot), cur_depth.eq(depth[seq_slot])]
                            m.next = "LOOKUP"
                        with m.Elif(state[seq_slot] == SlotState.SHOWN):
                            refuse(count.rows_shown)
                        with m.Else():
                            refuse(count.rows_duplicate)
                    with m.Elif(recv_active & (head.frame == recv_frame)):
                        m.d.sync += [cur_slot.eq(recv_slot), cur_depth.eq(depth[recv_slot])]
                        m.next = "LOOKUP"
                    with m.Elif(~last_valid | newer):
                        with m.If(recv_active):
                            take(recv_slot, abandon=True)
                        with m.Elif(free_found):
                            take(free_slot)
                        with m.Elif(~writing_found):
                            refuse(count.rows_no_slot)
                        # else wait: a slot frees when the frame being written becomes ready
                    with m.Elif(shown_match):
                        refuse(count.rows_shown)
                    with m.Else():
                        refuse(count.rows_stale)

            with m.State("CLEAR"):
                m.d.comb += [
                    bitmap_w.addr.eq(Cat(clear_index, cur_slot)),
                    bitmap_w.data.eq(0),
                    bitmap_w.en.eq(1),
                    occ_w.addr.eq(Cat(clear_index[:BLOCK_BITS], cur_slot)),
                    occ_w.data.eq(0),
                    occ_w.en.eq(Cat((clear_index < 2**BLOCK_BITS) for _ in range(PLANES))),
                ]
                m.d.sync += clear_index.eq(clear_index + 1)
                with m.If(clear_index == dmd.rows - 1):
                    m.d.sync += [
                        state[cur_slot].eq(SlotState.RECEIVING),
                        frame_id[cur_slot].eq(head.frame),
                        depth[cur_slot].eq(depth_in),
                        received[cur_slot].eq(0),
                        in_sequence[cur_slot].eq(sequence),
                        cur_depth.eq(depth_in),
                    ]
                    with m.If(~sequence):
                        m.d.sync += [recv_active.eq(1), recv_slot.eq(cur_slot), recv_frame.eq(head.frame),
                                     last_valid.eq(1), last_frame.eq(head.frame)]
                    m.next = "LOOKUP"

            with m.State("LOOKUP"):
                m.next = "DECIDE"                           # the bitmap bit of the row is read

            with m.State("DECIDE"):
                with m.If(bitmap_r.data):
                    refuse(count.rows_duplicate)
                with m.Else():
                    m.next = "PASS"

            with m.State("DROP"):
                with m.If(is_last):
                    m.d.comb += [self.words.ready.eq(self.rows.valid), self.rows.ready.eq(self.words.valid)]
                    with m.If(self.words.valid & self.rows.valid):
                        m.next = "ROW_START"
                with m.Else():
                    m.d.comb += self.words.ready.eq(1)

            with m.State("PASS"):
                with m.If(is_last):
                    both = self.words.valid & self.rows.valid
                    m.d.comb += [
                        self.store.valid.eq(both),
                        self.words.ready.eq(self.store.ready & self.rows.valid),
                        self.rows.ready.eq(self.store.ready & self.words.valid),
                    ]
                    with m.If(both & self.store.ready):
                        m.d.comb += [
                            bitmap_w.addr.eq(Cat(head.row, cur_slot)),
                            bitmap_w.data.eq(1),
                            bitmap_w.en.eq(1),
                            occ_w.addr.eq(Cat(flags.block, Const(0, BLOCK_BITS - len(flags.block)),
                                              cur_slot)),
                            occ_w.data.eq(~0),
                            occ_w.en.eq(flags.planes & stored_mask),
                        ]
                        m.d.sync += received[cur_slot].eq(received[cur_slot] + 1)
                        with m.If(received[cur_slot] == dmd.rows - 1):
                            m.d.sync += [state[cur_slot].eq(SlotState.WRITING),
                                         count.frames_complete.eq(count.frames_complete + 1)]
                            with m.If(~sequence):
                                m.d.sync += recv_active.eq(0)
                        m.next = "ROW_START"
                with m.Elif(head.plane + cur_depth >= PLANES):
                    m.d.comb += [self.store.valid.eq(self.words.valid), self.words.ready.eq(self.store.ready)]
                with m.Else():
                    m.d.comb += self.words.ready.eq(1)  # a plane below the frame's bit depth

        # -- the dmd side: asks and releases in, answers out
        m.submodules.commands = commands = AsyncFIFO(width=_Command.as_shape().size, depth=4,
                                                    w_domain="dmd", r_domain="sync")
        m.submodules.answers = answers = AsyncFIFO(width=FrameInfo.as_shape().size, depth=4,
                                                   w_domain="sync", r_domain="dmd")
        command_in = _Command(commands.w_data)
        m.d.comb += [
            commands.w_en.eq(self.ask.valid | self.release.valid),
            command_in.release.eq(self.release.valid),
            command_in.slot.eq(self.release.payload),
            self.release.ready.eq(commands.w_rdy),
            self.ask.ready.eq(commands.w_rdy & ~self.release.valid),
            self.frames.valid.eq(answers.r_rdy),
            self.frames.payload.eq(answers.r_data),
            answers.r_en.eq(self.frames.ready),
        ]
        command = _Command(commands.r_data)

        # -- housekeeping: one event per cycle, on slots the ingest does not touch
        ready_found, ready_slot = first_of(
            lambda s: (state[s] == SlotState.READY) & ~in_sequence[s])
        play = Signal(SLOT_BITS)
        loaded = Signal()
        m.d.comb += loaded.eq(1)
        for s in range(n_slots):
            with m.If((s < seq_len) & ~((state[s] == SlotState.READY) | (state[s] == SlotState.SHOWN))):
                m.d.comb += loaded.eq(0)
        answer_slot = Signal(SLOT_BITS)
        can_answer = Signal()
        with m.If(sequence):
            m.d.comb += [answer_slot.eq(play), can_answer.eq(loaded & (state[play] == SlotState.READY))]
        with m.Else():
            m.d.comb += [answer_slot.eq(ready_slot), can_answer.eq(ready_found)]
        answer = FrameInfo(answers.w_data)
        m.d.comb += [
            answer.slot.eq(answer_slot),
            answer.frame_id.eq(frame_id[answer_slot]),
            answer.bit_depth.eq(depth[answer_slot]),
        ]

        with m.If(mode_pending & ingest.ongoing("ROW_START")):
            m.d.sync += [seq_len.eq(wanted_len), play.eq(0), recv_active.eq(0), last_valid.eq(0)]
            for s in range(n_slots):
                with m.If(state[s] != SlotState.SHOWN):
                    m.d.sync += state[s].eq(SlotState.FREE)
                m.d.sync += in_sequence[s].eq(0)
        with m.Elif(self.written.valid):
            m.d.comb += self.written.ready.eq(1)
            done = self.written.payload
            with m.If(state[done] == SlotState.WRITING):
                m.d.sync += state[done].eq(SlotState.READY)
                # streaming: the newest complete frame replaces one never shown
                for s in range(n_slots):
                    with m.If((state[s] == SlotState.READY) & ~in_sequence[s] & ~in_sequence[done]
                              & (done != s)):
                        m.d.sync += [state[s].eq(SlotState.FREE),
                                     count.frames_replaced.eq(count.frames_replaced + 1)]
        with m.Elif(commands.r_rdy & command.release):
            m.d.comb += commands.r_en.eq(1)
            with m.If(state[command.slot] != SlotState.SHOWN):
                m.d.sync += count.bad_releases.eq(count.bad_releases + 1)
            with m.Elif(in_sequence[command.slot] & sequence):
                m.d.sync += state[command.slot].eq(SlotState.READY)
            with m.Else():
                m.d.sync += state[command.slot].eq(SlotState.FREE)
        with m.Elif(commands.r_rdy & can_answer & answers.w_rdy):
            m.d.comb += [commands.r_en.eq(1), answers.w_en.eq(1)]
            m.d.sync += state[answer_slot].eq(SlotState.SHOWN)
            with m.If(sequence):
                m.d.sync += play.eq(play + 1)
                with m.If(play == seq_len - 1):
                    m.d.sync += play.eq(0)
        return m
