"""What the sequencer's parts hand each other (all in the ``dmd`` domain).

The parts (:mod:`.planner`, :mod:`.control`, :mod:`.requester`, :mod:`.row_source`, :mod:`.bus`)
are joined by streams; an *event* is a stream that is always ready (it happens, it is not
offered), for example a clocking pulse made this cycle.
"""

from amaranth import Const, Mux
from amaranth.lib import data, stream, wiring
from amaranth.lib.wiring import In, Out
from amaranth.utils import ceil_log2

from ..registers import TIME_BITS, ResetMode
from ..store.layouts import COUNTER_BITS, SLOT_BITS
from .interface import BlockMode, RowMode

__all__ = ["group_bits", "block_bits", "group_span", "load_job", "ready_load", "dark_load", "event", "Command",
           "Status", "PulseSignature", "COUNTER_BITS"]


def group_bits(dmd):
    return max(1, ceil_log2(dmd.blocks))


block_bits = group_bits


def group_span(dmd, reset_mode, size_log2, group):
    """The first and last block of ``group``: every block in global mode, else ``2**size_log2``
    from ``group << size_log2``, cut at the last block (the DLP9500's 15 blocks)."""
    block_index_bits = block_bits(dmd)
    first = (group << size_log2)[:block_index_bits + 1]
    end = first | ((Const(1, 4) << size_log2) - 1)
    is_global = reset_mode == ResetMode.GLOBAL
    return (Mux(is_global, 0, first)[:block_index_bits],
            Mux(is_global | (end > dmd.blocks - 1), dmd.blocks - 1, end)[:block_index_bits])


def load_job(dmd):
    """What a group must be loaded with next: display position ``pos`` of the frame in ``slot``
    (of ``depth`` planes), the stored plane that is (``plane``), or a dark pulse's clears
    (``clear``: they go to the bus apart from the planes, :class:`~.bus.Bus` ``darks``)."""
    return data.StructLayout({"group": group_bits(dmd), "slot": SLOT_BITS, "depth": 4, "pos": 3, "plane": 3,
                              "clear": 1})


def ready_load(dmd):
    """A load job with its blocks looked up: ``mask`` bit b set when block b's rows are loaded
    (else it is cleared), for the blocks ``first`` .. ``last`` of the group; ``first_row``, the
    first block's first row; ``first_occupied``, ``mask``'s bit of ``first``, and ``single``, the
    job's first operation is its last (one block, cleared or of one row)."""
    return data.StructLayout({"group": group_bits(dmd), "mask": dmd.blocks,
                              "first": block_bits(dmd), "last": block_bits(dmd), "first_row": 11,
                              "first_occupied": 1, "single": 1})


def dark_load(dmd):
    """A dark pulse's clears: every block ``first`` .. ``last`` of ``group``."""
    return data.StructLayout({"group": group_bits(dmd), "first": block_bits(dmd), "last": block_bits(dmd)})


def event(shape):
    """An event port: a stream that is always ready."""
    return stream.Signature(shape, always_ready=True)


class Command(data.Struct):
    """The command pins of a row cycle, held through it."""
    rowmd: RowMode
    rowad: 11
    blkmd: BlockMode
    blkad: 4
    rst2blkz: 1


class Status(data.Struct):
    """Counters and the time base, for the status reply.

    ``now`` counts ``dmd`` cycles from the end of initialisation; ``frames`` frames started;
    ``triggers`` triggers obeyed; ``overruns`` triggers ignored because a frame was playing or
    the next one was not loaded yet; ``early`` triggers before initialisation ended; ``late``
    pulses made after their time (a parameter set the schedule model rejects); ``underruns``
    row loads that waited for their data from the store (one each); ``bad_frames`` frames offered with
    a bit depth outside 1..8, dropped; ``held`` triggers held until every group was ready;
    ``rst_late`` RST_ACTIVE falls later than planned (the settle counted from the fall);
    ``rst_faults`` RST_ACTIVE missing after a pulse or stuck high; ``restarts`` the controller
    initialised again mid-run (INIT_ACTIVE high again or ECP2_FINISHED low); ``rst_longest`` the
    longest RST_ACTIVE seen, in cycles from the pulse's decision; ``period_short`` frames started
    by the periodic timer whose planes outlast its period; ``after_end`` triggers ignored because
    a sequence played once had ended.
    """
    now: TIME_BITS
    frames: COUNTER_BITS
    triggers: COUNTER_BITS
    overruns: COUNTER_BITS
    early: COUNTER_BITS
    late: COUNTER_BITS
    underruns: COUNTER_BITS
    bad_frames: COUNTER_BITS
    held: COUNTER_BITS
    rst_late: COUNTER_BITS
    rst_faults: COUNTER_BITS
    restarts: COUNTER_BITS
    rst_longest: COUNTER_BITS
    period_short: COUNTER_BITS
    after_end: COUNTER_BITS


class PulseSignature(wiring.Signature):
    """The planner's flags to the bus and the bus's decision back, seen from the planner: each
    cycle the bus decides from the flags (registered by the planner) whether a group pulses,
    and the planner learns the decision and the loads that ended in the same cycle.

    Members
    -------
    due : Out(blocks)
        Bit g: group g is loaded, its pulse time has come and RST_ACTIVE's countdown allows it
        (the pin's own check is the bus's).
    due_fours : Out(ceil(blocks / 4))
        Bit q: some group of ``due[4q:4q + 4]`` is due: the bus finds the lowest due group from
        these without a chain over every flag.
    imminent, imminent_clear : Out(1)
        A loaded group's pulse falls due within a row, within a clear (and its no-op rows).
    writable : Out(blocks)
        Bit g: group g's memory may change (its settle time is over, counted from its pulse and
        from RST_ACTIVE's fall, and the frame control's lead).
    frees_soon, frees_soon_clear : Out(blocks)
        Bit g: group g's memory may change (``writable``), or its RST_ACTIVE count is over and its
        memory frees within a row, within a clear (and its no-op rows): a load operation would
        hold up its dark pulse's clears.
    choice : In(blocks)
        The bus's decision this cycle: bit g, a clocking pulse of group g (one bit at most).
    pulsing : In(1)
        Some bit of ``choice``.
    loaded : In(blocks)
        Bit g: group g's load ends this cycle (its last operation's last row cycle is on the pins
        by the next decision).
    """

    def __init__(self, blocks):
        self._blocks = blocks
        super().__init__({
            "due": Out(blocks),
            "due_fours": Out(-(-blocks // 4)),
            "imminent": Out(1),
            "imminent_clear": Out(1),
            "writable": Out(blocks),
            "frees_soon": Out(blocks),
            "frees_soon_clear": Out(blocks),
            "choice": In(blocks),
            "pulsing": In(1),
            "loaded": In(blocks),
        })

    def __eq__(self, other):
        return isinstance(other, PulseSignature) and other._blocks == self._blocks
