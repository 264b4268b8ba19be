"""The requester: turns load jobs into row requests to the store and ready loads for the bus.

For each job it looks up the occupancy map of the job's frame slot (one cycle), so that an
empty block is cleared instead of loaded; it hands the bus the job with its block mask first (so
the bus can drain one block's words while the next block's request waits for the store), then
asks the store for the rows of each occupied block, one request per block. It also hands slots
back: when the last group's first load comes from a new slot, no group reads the old one again.
While the frame control flushes, jobs are dropped here (through the same slot accounting) and a
request already offered is held until taken (its words are discarded by the row source).
"""

from amaranth import Cat, Module, Signal
from amaranth.lib import data, stream, wiring
from amaranth.lib.wiring import In, Out

from ..queue import Queue
from ..registers import Registers, Source
from ..store.layouts import SLOT_BITS, PlaneRequest
from .layouts import block_bits, group_span, load_job, ready_load

__all__ = ["Requester"]


class Requester(wiring.Component):
    """Load jobs to plane requests.

    Parameters
    ----------
    dmd : :class:`spec.facts.DmdType`

    Members
    -------
    regs : In(Registers)
    n_groups : In(range(blocks + 1))
    size_log2 : In(3)
        Blocks per group, log2 (phased modes).
    flushing : In(1)
        Drop jobs; end a request once it is taken.
    jobs : In(stream.Signature(load_job))
        Load jobs of planes in order (a dark pulse's clears go to the bus apart).
    occ_slot : Out(SLOT_BITS); occupancy : In(ArrayLayout(8, blocks))
        The occupancy read port (bit k of block b: stored plane k has a bit set in block b), for
        slot ``occ_slot`` as it was one cycle earlier.
    loads : Out(stream.Signature(ready_load))
        Each job with its block mask, to the bus.
    requests : Out(stream.Signature(PlaneRequest))
        One block of one plane per request, in load order.
    release : Out(stream.Signature(SLOT_BITS))
        Slots no group reads again.
    idle : Out(1)
        No job is being looked up or requested.
    """

    def __init__(self, dmd):
        self._dmd = dmd
        super().__init__({
            "regs": In(Registers),
            "n_groups": In(range(dmd.blocks + 1)),
            "size_log2": In(3),
            "flushing": In(1),
            "jobs": In(stream.Signature(load_job(dmd))),
            "occ_slot": Out(SLOT_BITS),
            "occupancy": In(data.ArrayLayout(8, dmd.blocks)),
            "loads": Out(stream.Signature(ready_load(dmd))),
            "requests": Out(stream.Signature(PlaneRequest)),
            "release": Out(stream.Signature(SLOT_BITS)),
            "idle": Out(1),
        })

    def _releases(self, m, taken, head, last_group):
        """Slots handed back, in order: a slot is released when the last group takes its first
        job from a newer slot (no group reads the old one again). A release is written the cycle
        after its job is taken, so a job is taken only with room for it and one more. Returns
        (``releasing``, ``room``)."""
        depth = 4
        m.submodules.releases = releases = Queue(SLOT_BITS, depth)
        wiring.connect(m, releases.r_stream, wiring.flipped(self.release))
        last_slot = Signal(SLOT_BITS)
        seen_slot = Signal()
        releasing, released = Signal(), Signal(SLOT_BITS)
        room = Signal()
        m.d.sync += [releasing.eq(0), room.eq(~releases.fill[depth - 3])]
        m.d.comb += [releases.w_stream.valid.eq(releasing), releases.w_stream.payload.eq(released)]
        leaves = (head.group == last_group) & seen_slot & (head.slot != last_slot)
        with m.If(taken & leaves):
            m.d.sync += [releasing.eq(1), released.eq(last_slot)]
        with m.If(taken & (head.group == last_group)):
            m.d.sync += [last_slot.eq(head.slot), seen_slot.eq(1)]
        return releasing, room

    def elaborate(self, platform):
        m = Module()
        dmd, regs, n_groups = self._dmd, self.regs, self.n_groups
        rows_per_block = dmd.rows_per_block
        block_index_bits = block_bits(dmd)
        use_prng = regs.source == Source.PRNG
        flushing = self.flushing

        entry = Signal(load_job(dmd))          # the job being requested
        mask = Signal(dmd.blocks)
        block = Signal(block_index_bits + 1)
        block_row = Signal(11)                 # the first row of ``block``
        first_row = Signal(11)
        first_occupied = Signal()
        occupied = Signal(dmd.blocks)          # each block's bit of the job's plane
        ahead = Signal(dmd.blocks)             # the mask from ``block`` on
        at_last = Signal()                     # ``block`` is the job's last block
        passed = Signal()                      # the last block's request is made (or skipped)
        last_group = Signal.like(self.n_groups)          # (the registers hold still)
        m.d.sync += last_group.eq(n_groups - 1)
        last = Signal(block_index_bits)
        head = self.jobs.payload
        plane = Signal(3)

        # the head job's plane, and its group's blocks, registered as the job is taken
        head_first, head_last = Signal(block_index_bits), Signal(block_index_bits)
        m.d.comb += Cat(head_first, head_last).eq(Cat(*group_span(dmd, regs.reset_mode, self.size_log2, head.group)))
        span_first, span_last = Signal(block_index_bits), Signal(block_index_bits)

        m.d.comb += [
            self.loads.payload.group.eq(entry.group), self.loads.payload.mask.eq(mask),
            self.loads.payload.first.eq(span_first), self.loads.payload.last.eq(last),
            self.loads.payload.first_row.eq(first_row),
            self.loads.payload.first_occupied.eq(first_occupied),
            self.loads.payload.single.eq((span_first == last) & (~first_occupied | (rows_per_block == 1))),
            self.requests.payload.slot.eq(entry.slot),
            self.requests.payload.plane.eq(plane),
            self.requests.payload.first_row.eq(block_row),
            self.requests.payload.row_count.eq(rows_per_block),
        ]

        # in IDLE, kept in a register of its own beside the state (set as the state goes to IDLE,
        # cleared as it leaves), so that taking a job does not wait on the state's decode
        idle = Signal(init=1)

        def goto(state):
            m.next = state
            m.d.sync += idle.eq(state == "IDLE")

        # a job is taken in IDLE
        taken = self.jobs.valid & self.jobs.ready
        releasing, room = self._releases(m, taken, head, last_group)
        m.d.comb += self.jobs.ready.eq(idle & room & ~releasing)
        # flushing: stale jobs are dropped here, through the same slot accounting
        with m.If(taken):
            m.d.sync += [entry.eq(head), span_first.eq(head_first), span_last.eq(head_last), plane.eq(head.plane)]

        with m.FSM(name="requester"):
            with m.State("IDLE"):
                with m.If(taken & ~flushing):
                    goto("LOOK")
            with m.State("LOOK"):
                # the slot's occupancy is answered now: each block's bit of the job's plane
                m.d.sync += occupied.eq(Cat(use_prng | self.occupancy[b].bit_select(plane, 1)
                                            for b in range(dmd.blocks)))
                goto("MASK")
                with m.If(flushing):
                    goto("IDLE")
            with m.State("MASK"):
                # (comparisons that cannot fail are left out: Verilator rejects them)
                def in_span(b):
                    after_first = (span_first <= b) if b < (1 << block_index_bits) - 1 else 1
                    before_last = (span_last >= b) if b else 1
                    return after_first & before_last
                looked = Cat(in_span(b) & occupied[b] for b in range(dmd.blocks))
                m.d.sync += [mask.eq(looked), block.eq(span_first), last.eq(span_last),
                             first_row.eq(span_first * rows_per_block), block_row.eq(span_first * rows_per_block),
                             first_occupied.eq(occupied.bit_select(span_first, 1)),
                             at_last.eq(span_first == span_last), passed.eq(0)]
                goto("PUSH")
                with m.If(flushing):
                    goto("IDLE")
            with m.State("PUSH"):
                # the bus learns the mask first, so it drains the words of one block while the
                # next block's request waits for the store
                with m.If(flushing):
                    goto("IDLE")
                with m.Else():
                    m.d.comb += self.loads.valid.eq(1)
                    # the requests to come: the mask from the first block on
                    m.d.sync += ahead.eq(mask >> span_first)
                    with m.If(self.loads.ready):
                        goto("REQUEST")
            with m.State("REQUEST"):
                wanted = ahead[0] & ~use_prng

                def next_block():
                    m.d.sync += [block.eq(block + 1), block_row.eq(block_row + rows_per_block), ahead.eq(ahead >> 1),
                                 at_last.eq(block + 1 == last), passed.eq(at_last)]
                # flushing: a request offered is held until taken (its words are discarded)
                with m.If(passed | (flushing & ~wanted)):
                    goto("IDLE")
                    m.d.sync += passed.eq(0)
                with m.Elif(wanted):
                    m.d.comb += self.requests.valid.eq(1)
                    with m.If(self.requests.ready):
                        next_block()
                        with m.If(flushing):
                            goto("IDLE")
                with m.Else():
                    next_block()
        # the occupancy of the head job's slot, answered the cycle after it is taken (in LOOK)
        m.d.comb += [self.idle.eq(idle), self.occ_slot.eq(head.slot)]
        return m
