"""The stream rules on every block with stream ports, and the properties of the small blocks.

Each entry of :data:`STREAM_BLOCKS` builds one block with small parameters (depths, geometry,
counter widths: the rules do not depend on them) and says which domain each top-level port
lives in; :func:`stream_checks` makes a :class:`~sim.formal.harness.Check` of each: the rules
assumed of the block's input streams and asserted of its output streams. Blocks in more than one
domain are checked with free, unrelated clocks (a free enable per domain, see
:mod:`sim.formal.harness`).

:func:`countdown_check` checks :class:`gateware.countdown.Countdown`'s flags against their
definition; :func:`register_crossing_check` that the sequencer's registers change only at rest.
"""

import dataclasses
from dataclasses import dataclass, field

from amaranth import Mux, Signal
from amaranth.asserts import AnyConst
from amaranth.hdl import Assert, Assume, Cover, Fragment

from .geometry import FORMAL_DMD
from .harness import Check, FormalTop
from .stream_properties import stream_rules

__all__ = ["STREAM_BLOCKS", "stream_checks", "countdown_check", "register_crossing_check", "checks"]

_ADDRESSES = {"mac": 0x02_00_00_00_00_01, "ip": 0xC0_A8_01_0A, "port": 5000}


@dataclass(frozen=True)
class StreamBlock:
    """A block to check the stream rules on: ``make()`` builds it; ``port_domains`` maps its
    ports to domains (default ``sync``); ``depth``/``induction``/``quick`` as in :class:`Check`
    (``quick`` None: a deep check, ``make formal`` only); ``uncovered``: output streams whose
    transfer lies beyond any bounded depth (their rule still asserted; the reason beside)."""
    name: str
    make: object
    depth: int
    induction: int | None = None
    domains: tuple = ("sync",)
    port_domains: dict = field(default_factory=dict)
    quick: int | None = 20
    parts: object = None
    resets: tuple = ()
    uncovered: tuple = ()


def _queue():
    from gateware.queue import Queue
    return Queue(8, 4)


def _async_queue():
    from gateware.queue import AsyncQueue
    return AsyncQueue(8, 4, w_domain="sync", r_domain="dmd")


def _rx_crossing():
    from gateware.mac.cdc import RxCrossing
    return RxCrossing(depth=8, max_frame=64, counter_width=4)


def _tx_crossing():
    from gateware.mac.cdc import TxCrossing
    return TxCrossing(depth=8)


def _receive_path():
    from gateware.mac.path import ReceivePath
    return ReceivePath(max_frame=64, depth=8, counter_width=4)


def _frame_buffer():
    from gateware.net.buffer import FrameBuffer
    return FrameBuffer(16)


def _net_transmitter():
    from gateware.net.transmit import Transmitter
    return Transmitter(sources=2)


def _stack():
    from gateware.net.stack import Stack
    return Stack(buffer_depth=64, descriptors=2)


def _parser():
    from gateware.protocol.parser import Parser, config_init
    return Parser(FORMAL_DMD, config_init(**_ADDRESSES))


def _status_reply():
    from gateware.protocol.status import StatusReply
    return StatusReply()


def _master_parser():
    from gateware.protocol.master import MasterParser, master_config_init
    return MasterParser(master_config_init(mode=0, armed=0, period=100, min_period=10, width=2))


def _serialiser():
    from gateware.bitplane.serialiser import Serialiser
    return Serialiser(FORMAL_DMD, lanes=8, frame_bits=2)


def _row_ingest():
    from gateware.store.row_ingest import RowIngest
    return RowIngest(FORMAL_DMD, slots=3, frame_bits=2)


def _slot_crossing():
    from gateware.store.slot_crossing import SlotCrossing
    return SlotCrossing(depth=2)


def _writer():
    from gateware.store.writer import Writer
    return Writer(FORMAL_DMD, slots=3, max_burst=2)


def _reader():
    # the product's 128-bit port, two plane words a transfer: rows of two words
    from gateware.store.reader import Reader
    dmd = dataclasses.replace(FORMAL_DMD, columns=128, visible_columns=128)
    return Reader(dmd, slots=3, fifo_depth=128, domain="sync", width=128)


def _split():
    from gateware.store.split import Split
    return Split(8, 2)


def _broker():
    from gateware.store.broker import FrameBroker
    return FrameBroker(FORMAL_DMD, slots=3)


def _frame_slots():
    from gateware.store.slots import FrameSlots
    return FrameSlots(FORMAL_DMD, slots=3, frame_bits=2)


_SLOTS_DMD = {"ask": "dmd", "frames": "dmd", "release": "dmd", "occupancy": "dmd"}


def _slot_parts(slots):
    """The parts of :class:`~gateware.store.slots.FrameSlots` and their ports' domains."""
    # (a memory that loses its calibration withdraws an answer on offer: the frame it named is
    # gone; the loss is a reset of the table's answers, as ``discard`` is of the writer's notice,
    # and no answer is lost, as none was taken)
    return [(name, part, _SLOTS_DMD if name in ("crossing", "maps") else {},
             *([part.lose] if name == "table" else []))
            for name, part in slots._parts.items()]

#: Every block with stream ports (the sequencer's parts are checked with the sequencer).
STREAM_BLOCKS = [
    StreamBlock("Queue", _queue, depth=24, induction=6),
    StreamBlock("AsyncQueue", _async_queue, depth=40, domains=("sync", "dmd"),
                port_domains={"r_stream": "dmd"}),
    StreamBlock("RxCrossing", _rx_crossing, depth=40, domains=("gmii_rx", "sync"),
                port_domains={"i": "gmii_rx", "dropped": "gmii_rx"}),
    # (each step past 28 doubles the solver's time: 40 would take hours)
    StreamBlock("TxCrossing", _tx_crossing, depth=28, domains=("sync", "gmii_tx"),
                port_domains={"o": "gmii_tx"}),
    StreamBlock("ReceivePath", _receive_path, depth=30, domains=("gmii_rx", "sync"),
                port_domains={"gmii": "gmii_rx"}),
    StreamBlock("FrameBuffer", _frame_buffer, depth=24, induction=4),
    StreamBlock("Transmitter", _net_transmitter, depth=24, induction=4),
    # (a datagram comes out at step 49 at the soonest: the Ethernet, IPv4 and UDP headers first)
    StreamBlock("Stack", _stack, depth=52, quick=None),
    # (a sequencer record is 150 bytes: its register set comes out past step 150, beyond a
    # bounded check; the rule on it is proven with the others by k-induction)
    StreamBlock("Parser", _parser, depth=20, induction=4, uncovered=("registers",)),
    StreamBlock("StatusReply", _status_reply, depth=20, induction=4),
    StreamBlock("MasterParser", _master_parser, depth=20, induction=4),
    StreamBlock("Serialiser", _serialiser, depth=24, induction=4),
    StreamBlock("RowIngest", _row_ingest, depth=24, induction=4),
    StreamBlock("SlotCrossing", _slot_crossing, depth=40, domains=("dmd", "sync"),
                port_domains={"ask": "dmd", "release": "dmd", "frames": "dmd"}),
    # (``discard`` resets the writer: the memory is lost, what it held is forgotten)
    StreamBlock("Writer", _writer, depth=24, induction=6, resets=("discard",)),
    StreamBlock("Reader", _reader, depth=24, induction=6),
    StreamBlock("Split", _split, depth=16, induction=2),
    StreamBlock("FrameBroker", _broker, depth=24, induction=6),
    # the slot table answers only for the slots its ingest opened and completed: its streams are
    # checked inside the frame slots, with every part's
    StreamBlock("FrameSlots", _frame_slots, depth=48, domains=("sync", "dmd"), port_domains=_SLOTS_DMD,
                parts=_slot_parts, quick=None),
]


def _top(block):
    dut = block.make()
    parts = block.parts(dut) if block.parts else ()
    return FormalTop(dut, [stream_rules(parts=parts, resets=block.resets, uncovered=block.uncovered)],
                     domains=block.domains,
                     port_domains=block.port_domains)


def stream_checks():
    return [Check("stream rules", block.name, lambda block=block: _top(block), depth=block.depth,
                  induction=block.induction, quick=block.quick and min(block.quick, block.depth))
            for block in STREAM_BLOCKS]


# -- Countdown --------------------------------------------------------------------------------

#: Limbs of 3 bits instead of 16 make every limb's borrow reachable in a few cycles; the limb
#: logic is the same at any limb width.
_LIMB = 3


def _countdown_top(width=7, within=(2, 5)):
    """Elaborated with short limbs: a reference count of the cycles since the load says what
    each flag must be."""
    from gateware import countdown
    saved = countdown.LIMB_BITS
    countdown.LIMB_BITS = _LIMB
    try:
        dut = countdown.Countdown(width, within=within)

        def definition(m, top):
            # t - c, the cycles since the load, saturating past the longest value
            loaded = Signal()
            value = Signal(width)
            elapsed = Signal(width + 1)
            with m.If(dut.load):
                m.d.sync += [loaded.eq(1), value.eq(dut.value), elapsed.eq(1)]
            with m.Elif(elapsed != 2**(width + 1) - 1):
                m.d.sync += elapsed.eq(elapsed + 1)
            # before any load the timer's time has come (it starts done)
            with m.If(loaded):
                m.d.comb += [
                    Assert(dut.done == (elapsed >= value), "done is t >= T"),
                    Assert(dut.late == (elapsed > value), "late is t > T"),
                ]
                for i, k in enumerate(within):
                    m.d.comb += Assert(dut.within[i] == (value < elapsed + k), f"within[{i}] is T - t < {k}")
            with m.Else():
                m.d.comb += Assert(dut.done & dut.late & dut.within.all(), "a timer never loaded is late")
            # the subject: a load's time coming, past a borrow between limbs, and its time passing
            m.d.comb += [Cover(loaded & dut.done & ~dut.late & (value > 2**_LIMB), "a load's time comes, across limbs"),
                         Cover(loaded & dut.late & (elapsed == value + 1) & (value > 2**_LIMB), "a load's time passes")]

        return Fragment.get(FormalTop(dut, [definition]), None)
    finally:
        countdown.LIMB_BITS = saved


def countdown_check():
    return Check("flags against their definition", "Countdown", _countdown_top, depth=2**7 + 8,
                 induction=2**7 + 4, quick=24, quick_proof=False)


# -- RegisterCrossing ---------------------------------------------------------------------------

def _register_crossing_top():
    from gateware.dlpc410.register_crossing import RegisterCrossing
    from gateware.registers import TriggerMode
    dut = RegisterCrossing({}, depth=2)

    def at_rest_only(m, top):
        # the registers the sequencer runs with change only in a dmd cycle it rests in; arming
        # gates two of them (chain low, trigger software while disarmed) a cycle later, so a
        # change of ``armed`` may change those two while the sequencer runs, and nothing else
        regs = dut.regs.as_value()
        before = Signal.like(regs)
        rested, started = Signal(), Signal()
        armed_1, armed_2 = Signal(init=1), Signal(init=1)     # ``armed`` one and two cycles ago
        m.d.dmd += [before.eq(regs), rested.eq(dut.at_rest), armed_1.eq(dut.armed), armed_2.eq(armed_1),
                    started.eq(1)]
        with m.If(started & ~rested & (armed_1 == armed_2)):
            m.d.comb += Assert(regs == before, "regs changed while the sequencer ran")
        with m.If(~armed_1):
            m.d.comb += [Assert(~dut.regs.chain, "chained while disarmed"),
                         Assert(dut.regs.trigger == TriggerMode.SOFTWARE,
                                "a trigger mode other than software while disarmed")]
        # the subject: sets applied at rest, and arming changing while the sequencer runs
        m.d.comb += [Cover(dut.applied == 2, "two sets applied"),
                     Cover(started & ~rested & (armed_1 != armed_2) & (dut.applied != 0),
                           "arming changed while the sequencer ran with a set applied")]

    return FormalTop(dut, [stream_rules(), at_rest_only], domains=("sync", "dmd"),
                     port_domains={"at_rest": "dmd", "regs": "dmd", "reload": "dmd", "applied": "dmd"})


def register_crossing_check():
    return Check("registers change only at rest (arming aside); stream rules", "RegisterCrossing",
                 _register_crossing_top, depth=40, quick=12)


# -- SlotStates ------------------------------------------------------------------------------------

def _slot_states_top():
    from gateware.store.slot_states import SlotStates
    dut = SlotStates(4, views=("place",))

    def last_write_wins(m, top):
        # one slot, any: once written, each field reads as the last value either writer wrote
        # to it (the two writers never write one slot on the same cycle: the slot table's
        # promise, assumed; the contents before any write are the memory's initial zeros, which
        # the solver does not know of, so the fields are compared once written)
        k = AnyConst(2)
        ing, hk = dut.ingest_write, dut.housekeeping_write
        state, in_sequence, depth, stale = Signal(3), Signal(), Signal(4), Signal()
        known_phase, known_depth, known_stale = Signal(), Signal(), Signal()
        m.d.comb += [dut.place.slot.eq(k), Assume(~(ing.en & hk.en & (ing.slot == dut.housekeeping.slot))),
                     Assume(ing.slot < 4), Assume(dut.housekeeping.slot < 4)]      # the slots there are
        with m.If(ing.en & (ing.slot == k)):
            m.d.sync += [state.eq(ing.phase.state), in_sequence.eq(ing.phase.in_sequence), known_phase.eq(1)]
            with m.If(ing.depth_en):
                m.d.sync += [depth.eq(ing.depth), known_depth.eq(1)]
        with m.If(hk.en & (dut.housekeeping.slot == k)):
            m.d.sync += [state.eq(hk.phase.state), in_sequence.eq(hk.phase.in_sequence), stale.eq(hk.stale),
                         known_phase.eq(1), known_stale.eq(1)]
        view = dut.place
        with m.If(known_phase):
            m.d.comb += [Assert(view.state == state, "state"), Assert(view.in_sequence == in_sequence, "in_sequence")]
        with m.If(known_depth):
            m.d.comb += Assert(view.depth == depth, "depth")
        with m.If(known_stale):
            m.d.comb += Assert(view.stale == stale, "stale")
        # the subject: a slot written by both writers, read back
        m.d.comb += Cover(known_depth & known_stale & (view.depth != 0) & view.stale, "a slot written by both writers")

    return FormalTop(dut, [last_write_wins], driven=("place",))


def slot_states_check():
    return Check("each slot reads the last value written by either writer", "SlotStates", _slot_states_top,
                 depth=8, induction=4, quick=8)


# -- SyncMaster ------------------------------------------------------------------------------------

def _sync_master_top(boards=3):
    from amaranth.lib.cdc import FFSynchronizer

    from gateware.sync.master import SyncMaster
    dut = SyncMaster(boards)

    def pulses_keep_their_rules(m, top):
        # the frame timing held from the start (as the master's configuration holds between
        # records), any trigger source, any ready lines: every board's line and the camera's the
        # same on every cycle; a pulse starts only on a trigger obeyed (armed, every board ready
        # as the master synchronised its lines, ``min_period`` since the last start), lasts
        # ``width`` cycles, and is counted once
        min_period, width = AnyConst(6), AnyConst(4)
        m.d.comb += [dut.min_period.eq(min_period), dut.width.eq(width), Assume(width >= 1),
                     Assume(width < min_period)]
        ready = Signal(boards)
        m.submodules.ready_sync = FFSynchronizer(dut.ready, ready)    # what the master sees
        out, was, seen, since, high = dut.sync_out, Signal(), Signal(), Signal(7), Signal(5)
        started = out[0] & ~was
        m.d.sync += [was.eq(out[0]), seen.eq(seen | started),
                     since.eq(Mux(started, 1, Mux(since == 127, 127, since + 1))),
                     high.eq(Mux(out[0], Mux(high == 31, 31, high + 1), 0))]
        counted, pulses_before, allowed = Signal(), Signal.like(dut.pulses), Signal()
        m.d.sync += [pulses_before.eq(dut.pulses), allowed.eq(dut.run & ready.all())]
        m.d.comb += [Assert(out == Mux(out[0], (1 << boards) - 1, 0), "every sync line the same"),
                     Assert(dut.camera_out == out[0], "the camera line with them")]
        pending = Signal()          # a trigger obeyed last cycle: its pulse starts now
        m.d.sync += pending.eq(dut.pulses != pulses_before)
        m.d.comb += counted.eq(dut.pulses != pulses_before)
        with m.If(started):
            m.d.comb += Assert(pending, "a pulse starts only the cycle after a trigger is obeyed")
        with m.If(counted):
            m.d.comb += [Assert(allowed, "obeyed only while armed with every board ready"),
                         Assert(dut.pulses == pulses_before + 1, "counted once")]
        with m.If(started & seen & (since != 127)):
            m.d.comb += Assert(since >= min_period, "pulses at least min_period apart")
        with m.If(was & ~out[0]):
            m.d.comb += Assert(high == width, "each pulse lasts width cycles")
        # the subject: a second pulse, and a pulse refused for a board not ready
        m.d.comb += [Cover(started & seen & (since != 127), "a second pulse"),
                     Cover(dut.not_ready != 0, "a pulse refused for a board not ready")]

    return FormalTop(dut, [pulses_keep_their_rules], driven=("min_period", "width"))


def sync_master_check():
    return Check("pulses: on every line at once, only when obeyed, min_period apart, width long", "SyncMaster",
                 _sync_master_top, depth=40, induction=20, quick=24)


def checks():
    """Every check of this module."""
    return [*stream_checks(), countdown_check(), register_crossing_check(), slot_states_check(),
            sync_master_check()]
