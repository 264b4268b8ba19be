"""The DLPC410 load/reset sequencer: PWM frames, phased and global pulses.

It plays the algorithm documented in :mod:`spec.schedule` (the model it must match
cycle for cycle): per pulse group a timeline of clocking pulses at exact cycles, loads queued in
pulse order and served behind the settle time, dark pulses of cleared blocks for short planes,
and a first plane preloaded so that a trigger becomes a pulse a few cycles later.

Inside, three small engines share the command bus:

* the *planner* runs when a group is pulsed: it sets the group's next pulse time and queues
  what the group must be loaded with (a plane, or clears);
* the *requester* takes queued loads, reads the occupancy map and asks the store for the rows of
  the occupied blocks (:class:`gateware.store.layouts.PlaneRequest`);
* the *bus* decides every even cycle on which no row cycle runs: a pulse that is due, else the
  next row load or block clear, else nothing.
"""

from amaranth import Array, Cat, Const, Module, Mux, Signal
from amaranth.lib import data, fifo, stream, wiring
from amaranth.lib.wiring import In, Out
from amaranth.utils import ceil_log2

from spec.schedule import INIT_TO_DVALID, WORD_FIFO_ROWS, flush_rows

from ..registers import DURATION_BITS, TIME_BITS, PlaneOrder, Registers, ResetMode, Source
from ..store.layouts import SLOT_BITS, FrameInfo, PlaneRequest
from . import interface
from .beat import beat_lanes
from .init import TRAINING_EDGES, Init
from .interface import BlockMode, RowMode
from .prng import Prng
from .trigger import Trigger

__all__ = ["Sequencer", "Status"]

COUNTER_BITS = 16


class Status(data.Struct):
    """Counters and the time base, for the status reply.

    ``now`` counts ``dmd`` cycles from the end of initialisation; ``frames`` frames started;
    ``triggers`` triggers obeyed; ``overruns`` triggers ignored because a frame was playing or
    the next one was not loaded yet; ``early`` triggers before initialisation ended; ``late``
    pulses made after their time (a parameter set the schedule model rejects); ``underruns``
    bus decisions that waited for row data from the store; ``bad_frames`` frames offered with
    a bit depth outside 1..8, dropped.
    """
    now: TIME_BITS
    frames: COUNTER_BITS
    triggers: COUNTER_BITS
    overruns: COUNTER_BITS
    early: COUNTER_BITS
    late: COUNTER_BITS
    underruns: COUNTER_BITS
    bad_frames: COUNTER_BITS


def _diff(a, b):
    """``a - b`` as a signed time difference (the time base may wrap)."""
    return (a - b)[:TIME_BITS].as_signed()


def _exponent(m, regs, j, depth, name):
    """Weight exponent of display position ``j`` in a frame of ``depth`` planes."""
    e = Signal(3, name=name)
    with m.Switch(regs.order):
        with m.Case(PlaneOrder.MSB_FIRST):
            m.d.comb += e.eq(depth - 1 - j)
        with m.Case(PlaneOrder.LSB_FIRST):
            m.d.comb += e.eq(j)
        with m.Default():
            m.d.comb += e.eq(regs.order_table[j])
    return e


class Sequencer(wiring.Component):
    """DLPC410 sequencer for two-bus (DLP7000) and four-bus (DLP9500) DMDs.

    Parameters
    ----------
    dmd : :class:`spec.facts.DmdType`
        Geometry: a beat of ``bits_per_dclk`` bits per DCLK cycle (one 64-bit word on A/B, and
        a second on C/D for four buses), ``dclk_per_row`` beats per row; a block clear takes
        ``clear_row_cycles`` row cycles (1080p: the clear and two no-op rows; facts table).
        The store gives one word per cycle at most, so a four-bus DMD loads a row every two
        row cycles at best (the plan's ``row_period``).

    Members
    -------
    pins : Out(:class:`gateware.dlpc410.interface.Signature`)
        The DLPC410 applications interface.
    regs : In(:class:`gateware.registers.Registers`)
        Run-time parameters. Change them only while ``at_rest`` is high, with ``reload``.
    at_rest : Out(1)
        No frame is playing and no load is under way: before the first frame, or every group
        loaded and waiting for a trigger (a chained run waits so only for its first trigger).
        The only time ``regs`` may change.
    reload : In(1)
        One cycle, while ``at_rest``, in the cycle ``regs`` change: every group's first plane is
        loaded again under the new registers (the reset mode and plane order decide what that
        is), as for a newer frame offered while waiting; a trigger in that cycle is an overrun.
    trigger_in, sync_in : In(1)
        TTL trigger and sync inputs (asynchronous).
    soft_trigger : In(1)
        Software trigger, a one-cycle pulse.
    sync_out : Out(1)
        High while a frame is shown (first pulse to the last group's final dark pulse).
    camera_out : Out(1)
        Camera trigger: ``camera_width`` cycles, starting ``camera_offset`` cycles after the
        frame's first clocking pulse appears on the pins.
    frames : In(stream.Signature(FrameInfo))
        The newest complete frame; taken when a new frame is due (else the last one repeats),
        or, triggered and not chained, as soon as every group waits loaded for a trigger: the
        first plane is then loaded again from the new frame (a trigger meanwhile is an overrun).
    requests : Out(stream.Signature(PlaneRequest))
        Rows to read, one block of one plane per request, in load order.
    words : In(stream.Signature(64))
        The requested rows' words, in order (paired into beats for four buses).
    occ_slot : Out(SLOT_BITS), occupancy : In(ArrayLayout(8, blocks))
        Occupancy read port: per block a byte, bit k set when stored plane k has a bit set
        in the block, for slot ``occ_slot`` as it was one cycle earlier.
    seed, reseed : In(64), In(1)
        Seed of the Bernoulli pattern source.
    release : Out(stream.Signature(SLOT_BITS))
        A slot the sequencer will request no more rows from (every group has moved on to a
        frame in another slot); the store may reuse it once it has answered those requests.
    status : Out(Status)
    """

    def __init__(self, dmd):
        assert dmd.buses in (2, 4) and dmd.bits_per_dclk == 32 * dmd.buses
        assert dmd.words_per_row * 64 == dmd.dclk_per_row * dmd.bits_per_dclk
        self._dmd = dmd
        super().__init__({
            "pins": Out(interface.Signature(dmd.buses)),
            "regs": In(Registers),
            "at_rest": Out(1),
            "reload": In(1),
            "trigger_in": In(1),
            "sync_in": In(1),
            "soft_trigger": In(1),
            "sync_out": Out(1),
            "camera_out": Out(1),
            "frames": In(stream.Signature(FrameInfo)),
            "requests": Out(stream.Signature(PlaneRequest)),
            "words": In(stream.Signature(64)),
            "occ_slot": Out(SLOT_BITS),
            "occupancy": In(data.ArrayLayout(8, dmd.blocks)),
            "seed": In(64),
            "reseed": In(1),
            "release": Out(stream.Signature(SLOT_BITS)),
            "status": Out(Status),
        })

    def elaborate(self, platform):
        m = Module()
        dmd = self._dmd
        regs = self.regs
        R = dmd.dclk_per_row
        GMAX = dmd.blocks
        rpb = dmd.rows_per_block
        blk_bits = max(1, ceil_log2(dmd.blocks))
        grp_bits = max(1, ceil_log2(dmd.blocks))

        m.submodules.init = init = Init()
        m.submodules.trigger = trig = Trigger()
        wpb = dmd.bits_per_dclk // 64         # words per beat
        m.submodules.prng = prng = Prng(words=wpb)
        m.submodules.fifo = words = fifo.SyncFIFOBuffered(width=dmd.bits_per_dclk, depth=WORD_FIFO_ROWS * R)
        m.d.comb += [
            init.ecp2_finished.eq(self.pins.ecp2_finished),
            init.init_active.eq(self.pins.init_active),
            init.rst_active.eq(self.pins.rst_active),
            trig.mode.eq(regs.trigger), trig.period.eq(regs.period), trig.run.eq(init.running),
            trig.pin.eq(self.trigger_in), trig.sync_in.eq(self.sync_in), trig.soft.eq(self.soft_trigger),
            prng.seed.eq(self.seed), prng.reseed.eq(self.reseed),
        ]
        if wpb == 1:
            m.d.comb += [words.w_data.eq(self.words.payload), words.w_en.eq(self.words.valid),
                         self.words.ready.eq(words.w_rdy)]
        else:
            # four buses: the first word of a beat waits for the second (A/B, then C/D)
            first = Signal(64)
            have = Signal()
            m.d.comb += [words.w_data.eq(Cat(first, self.words.payload)),
                         words.w_en.eq(self.words.valid & have),
                         self.words.ready.eq(~have | words.w_rdy)]
            with m.If(self.words.valid & self.words.ready):
                m.d.sync += [first.eq(self.words.payload), have.eq(~have)]
        use_prng = regs.source == Source.PRNG

        now = self.status.now
        with m.If(init.running):
            m.d.sync += now.eq(now + 1)

        # ---- groups: how the reset mode splits the blocks ----
        n_groups = Signal(range(GMAX + 1))
        size_log2 = Signal(3)
        with m.Switch(regs.reset_mode):
            with m.Case(ResetMode.GLOBAL):
                m.d.comb += n_groups.eq(1)
            with m.Case(ResetMode.QUAD):
                m.d.comb += [n_groups.eq((dmd.blocks + 3) // 4), size_log2.eq(2)]
            with m.Case(ResetMode.DUAL):
                m.d.comb += [n_groups.eq((dmd.blocks + 1) // 2), size_log2.eq(1)]
            with m.Case(ResetMode.SINGLE):
                m.d.comb += n_groups.eq(dmd.blocks)

        def group_span(g):
            """(first, last) block of group ``g`` (a signal)."""
            first = Mux(regs.reset_mode == ResetMode.GLOBAL, 0, (g << size_log2)[:blk_bits + 1])
            end = Mux(regs.reset_mode == ResetMode.GLOBAL, dmd.blocks - 1,
                      first + (Const(1, 4) << size_log2) - 1)
            return first, Mux(end > dmd.blocks - 1, dmd.blocks - 1, end)

        # ---- per-group state ----
        def per_group(shape, name, init=0):
            return Array(Signal(shape, name=f"{name}{g}", init=init) for g in range(GMAX))
        pending = per_group(1, "pending")
        loaded = per_group(1, "loaded")
        pulse_at = per_group(TIME_BITS, "pulse_at")
        writable = per_group(TIME_BITS, "writable", INIT_TO_DVALID)
        rst_free = per_group(TIME_BITS, "rst_free")
        pos = per_group(3, "pos")
        dark = per_group(1, "dark")
        slot = per_group(SLOT_BITS, "slot")
        depth = per_group(4, "depth")
        rst_any = Signal(TIME_BITS)
        active = [Signal(name=f"active{g}") for g in range(GMAX)]
        for g in range(GMAX):
            m.d.comb += active[g].eq(g < n_groups)

        next_slot = Signal(SLOT_BITS)
        next_depth = Signal(4)
        take_idle = Signal()                   # a frame offered while no group plays
        flushing = Signal()                    # stale loads dropped, their words discarded
        # words asked of the store and not yet taken from the word FIFO
        owed = Signal(range((GMAX + 2) * dmd.words_per_plane + 1))

        # ---- load queue (pulse order) -> requester -> loader queue ----
        queued = data.StructLayout({"group": grp_bits, "slot": SLOT_BITS, "depth": 4, "pos": 3, "clear": 1})
        ready_load = data.StructLayout({"group": grp_bits, "mask": dmd.blocks,
                                        "first": blk_bits, "last": blk_bits})
        m.submodules.queue = queue = fifo.SyncFIFOBuffered(width=queued.size, depth=GMAX + 1)
        m.submodules.loads = loads = fifo.SyncFIFOBuffered(width=ready_load.size, depth=GMAX + 1)
        enq = Signal(queued)
        m.d.comb += queue.w_data.eq(enq)

        # ---- requester ----
        req_entry = Signal(queued)
        req_mask = Signal(dmd.blocks)
        req_block = Signal(blk_bits + 1)
        req_first = Signal(blk_bits)
        req_last = Signal(blk_bits)
        head = data.View(queued, queue.r_data)
        m.d.comb += self.occ_slot.eq(head.slot)
        req_exp = _exponent(m, regs, req_entry.pos, req_entry.depth, "req_exp")
        req_plane = Signal(3)
        m.d.comb += req_plane.eq(8 - req_entry.depth + req_exp)
        r_first, r_last = group_span(req_entry.group)
        loads_in = Signal(ready_load)
        m.d.comb += [
            loads_in.group.eq(req_entry.group), loads_in.mask.eq(req_mask),
            loads_in.first.eq(req_first), loads_in.last.eq(req_last),
            loads.w_data.eq(loads_in),
            self.requests.payload.slot.eq(req_entry.slot),
            self.requests.payload.plane.eq(req_plane),
            self.requests.payload.first_row.eq(req_block * rpb),
            self.requests.payload.row_count.eq(rpb),
        ]
        m.submodules.releases = releases = fifo.SyncFIFOBuffered(width=SLOT_BITS, depth=4)
        last_slot = Signal(SLOT_BITS)
        seen_slot = Signal()
        m.d.comb += [
            releases.w_data.eq(last_slot),
            self.release.valid.eq(releases.r_rdy), self.release.payload.eq(releases.r_data),
            releases.r_en.eq(self.release.ready),
        ]
        with m.FSM(name="requester") as requester:
            with m.State("IDLE"):
                # the last group's first load from a new slot: no group reads the old one again
                leaves = (head.group == n_groups - 1) & ~head.clear & seen_slot & (head.slot != last_slot)
                # flushing: stale entries are dropped here, through the same slot accounting
                with m.If(queue.r_rdy & (~leaves | releases.w_rdy)):
                    m.d.comb += [queue.r_en.eq(1), releases.w_en.eq(leaves)]
                    m.d.sync += req_entry.eq(head)
                    with m.If((head.group == n_groups - 1) & ~head.clear):
                        m.d.sync += [last_slot.eq(head.slot), seen_slot.eq(1)]
                    with m.If(~flushing):
                        m.next = "LOOK"
            with m.State("LOOK"):
                mask = Cat(
                    (b >= r_first) & (b <= r_last) & ~req_entry.clear
                    & (use_prng | self.occupancy[b].bit_select(req_plane, 1))
                    for b in range(dmd.blocks))
                m.d.sync += [req_mask.eq(mask), req_block.eq(r_first),
                             req_first.eq(r_first), req_last.eq(r_last)]
                m.next = "PUSH"
                with m.If(flushing):
                    m.next = "IDLE"
            with m.State("PUSH"):
                # the loader learns the mask first, so it drains the words of one block while
                # the next block's request waits for the store
                with m.If(flushing):
                    m.next = "IDLE"
                with m.Else():
                    m.d.comb += loads.w_en.eq(1)
                    with m.If(loads.w_rdy):
                        m.next = "REQUEST"
            with m.State("REQUEST"):
                wanted = req_mask.bit_select(req_block, 1) & ~use_prng
                # flushing: a request offered is held until taken (its words are discarded)
                with m.If((req_block > req_last) | (flushing & ~wanted)):
                    m.next = "IDLE"
                with m.Elif(wanted):
                    m.d.comb += self.requests.valid.eq(1)
                    with m.If(self.requests.ready):
                        m.d.sync += req_block.eq(req_block + 1)
                        with m.If(flushing):
                            m.next = "IDLE"
                with m.Else():
                    m.d.sync += req_block.eq(req_block + 1)

        # ---- the bus ----
        remain = Signal(range(R))              # cycles of the running row cycle after this one
        noops = Signal(range(dmd.clear_row_cycles))   # no-op rows still owed to a clear
        free = (remain == 0) & ~now[0] & (noops == 0)
        clear_len = dmd.clear_row_cycles * R
        op_row = Signal()                      # the running row cycle loads a row
        finishing = Signal()
        finish_group = Signal(grp_bits)

        cmd = Signal(data.StructLayout({"rowmd": RowMode, "rowad": 11, "blkmd": BlockMode,
                                        "blkad": 4, "rst2blkz": 1}))
        dvalid = Signal()
        word = Signal(dmd.bits_per_dclk)

        rst_ok = [Mux(regs.strict_rst, _diff(rst_any, now) <= 0, _diff(rst_free[g], now) <= 0)
                  & ~init.rst_active_synced for g in range(GMAX)]
        armed = [Signal(name=f"armed{g}") for g in range(GMAX)]
        due = Signal(GMAX)
        imminent = Signal()                    # a loaded pulse falls due within a row cycle
        imminent_clear = Signal()              # ... within a clear and its no-op rows
        for g in range(GMAX):
            m.d.comb += [
                armed[g].eq(active[g] & pending[g] & loaded[g]),
                due[g].eq(armed[g] & (_diff(pulse_at[g], now) <= 0) & rst_ok[g]),
            ]
        m.d.comb += [
            imminent.eq(Cat(armed[g] & (_diff(pulse_at[g], now) < R) for g in range(GMAX)).any()),
            imminent_clear.eq(Cat(armed[g] & (_diff(pulse_at[g], now) < clear_len) for g in range(GMAX)).any()),
        ]
        p = Signal(grp_bits)                   # the group pulsed this cycle
        for g in reversed(range(GMAX)):
            with m.If(due[g]):
                m.d.comb += p.eq(g)

        running = Signal()                     # a frame is known and the first loads are queued
        do_pulse = Signal()
        m.d.comb += do_pulse.eq(running & free & due.any())

        # loader view of the head of the ready loads
        lhead = data.View(ready_load, loads.r_data)
        fresh = Signal(init=1)
        l_block = Signal(blk_bits)
        l_row = Signal(range(rpb))
        cur_block = Mux(fresh, lhead.first, l_block)
        cur_row = Mux(fresh, 0, l_row)
        occupied = lhead.mask.bit_select(cur_block, 1)
        next_row_at = Signal(TIME_BITS)
        data_ok = use_prng | (words.level >= R)
        l_group = lhead.group
        can_load = (running & ~flushing & free & ~do_pulse & loads.r_rdy
                    & (_diff(writable[l_group], now) <= 0))
        row_ready = (_diff(next_row_at, now) <= 0)
        do_row = Signal()
        do_clear = Signal()
        m.d.comb += [
            do_row.eq(can_load & ~imminent & occupied & row_ready & data_ok),
            do_clear.eq(can_load & ~imminent_clear & ~occupied),
        ]
        last_op = (cur_block == lhead.last) & (~occupied | (cur_row == rpb - 1))
        underrun = can_load & ~imminent & occupied & row_ready & ~data_ok
        with m.If(underrun):
            m.d.sync += self.status.underruns.eq(self.status.underruns + 1)

        with m.If(do_row | do_clear):
            with m.If(last_op):
                m.d.comb += loads.r_en.eq(1)
                m.d.sync += [fresh.eq(1), finishing.eq(1), finish_group.eq(l_group)]
            with m.Else():
                m.d.sync += fresh.eq(0)
                with m.If(occupied & (cur_row != rpb - 1)):
                    m.d.sync += [l_block.eq(cur_block), l_row.eq(cur_row + 1)]
                with m.Else():
                    m.d.sync += [l_block.eq(cur_block + 1), l_row.eq(0)]
        with m.If(do_row):
            m.d.sync += next_row_at.eq(now + regs.row_period)
        with m.If(finishing & (remain == 1) & (noops == 0)):
            m.d.sync += [loaded[finish_group].eq(1), finishing.eq(0)]

        # ---- the command registers ----
        issue = do_pulse | do_row | do_clear
        reading = do_row | (op_row & (remain != 0))
        discard = flushing & ~reading & (owed != 0)
        m.d.comb += [words.r_en.eq(reading & ~use_prng | discard), prng.next.eq(reading & use_prng)]
        asked = Mux(self.requests.valid & self.requests.ready, rpb * dmd.words_per_row, 0)
        m.d.sync += owed.eq(owed + asked - Mux(words.r_en & words.r_rdy, wpb, 0))
        with m.If(flushing):
            m.d.comb += loads.r_en.eq(1)
        m.d.sync += word.eq(Mux(reading, Mux(use_prng, prng.word, words.r_data), 0))
        with m.If(issue):
            m.d.sync += [dvalid.eq(1), remain.eq(R - 1), op_row.eq(do_row),
                         cmd.rowmd.eq(RowMode.NOOP), cmd.blkmd.eq(BlockMode.NOOP),
                         cmd.rowad.eq(0), cmd.blkad.eq(0), cmd.rst2blkz.eq(1)]
            with m.If(do_row):
                m.d.sync += [cmd.rowmd.eq(RowMode.ADDRESSED), cmd.rowad.eq(cur_block * rpb + cur_row)]
            with m.Elif(do_clear):
                m.d.sync += [cmd.blkmd.eq(BlockMode.CLEAR), cmd.blkad.eq(cur_block),
                             noops.eq(dmd.clear_row_cycles - 1)]
            with m.Else():
                with m.Switch(regs.reset_mode):
                    with m.Case(ResetMode.GLOBAL):
                        m.d.sync += [cmd.blkmd.eq(BlockMode.MULTI), cmd.blkad.eq(0b1000)]
                    with m.Case(ResetMode.QUAD):
                        m.d.sync += [cmd.blkmd.eq(BlockMode.MULTI), cmd.blkad.eq(p << 1)]
                    with m.Case(ResetMode.DUAL):
                        m.d.sync += [cmd.blkmd.eq(BlockMode.MULTI), cmd.blkad.eq(p), cmd.rst2blkz.eq(0)]
                    with m.Case(ResetMode.SINGLE):
                        m.d.sync += [cmd.blkmd.eq(BlockMode.RESET), cmd.blkad.eq(p)]
        with m.Elif(remain != 0):
            m.d.sync += remain.eq(remain - 1)
        with m.Elif(noops != 0):
            # the clear's no-op rows follow it back to back (1080p), DVALID high
            m.d.sync += [remain.eq(R - 1), noops.eq(noops - 1), cmd.blkmd.eq(BlockMode.NOOP),
                         cmd.blkad.eq(0)]
        with m.Else():
            m.d.sync += [dvalid.eq(0), op_row.eq(0), cmd.rowmd.eq(RowMode.NOOP),
                         cmd.blkmd.eq(BlockMode.NOOP), cmd.rst2blkz.eq(1)]

        # ---- the planner: what follows a pulse of group p ----
        pj, pdark, pdepth = pos[p], dark[p], depth[p]
        pe = _exponent(m, regs, pj, pdepth, "pulse_exp")
        last = pj == pdepth - 1
        plane_len = Signal.like(regs.hide)
        m.d.comb += plane_len.eq(regs.lsb << pe)
        hidden = ~pdark & (plane_len >= regs.hide) & (~last | regs.chain)
        new_frame = last & (pdark | hidden)
        # a frame with a bit depth outside 1..8 is dropped as soon as it is offered, and counted
        depth_in = self.frames.payload.bit_depth
        frame_ok = (depth_in != 0) & (depth_in <= 8)
        with m.If(self.frames.valid & ~frame_ok):
            m.d.comb += self.frames.ready.eq(1)
            m.d.sync += self.status.bad_frames.eq(self.status.bad_frames + 1)
        take = Signal()
        n_slot = Mux(take, self.frames.payload.slot, next_slot)
        n_depth = Mux(take, self.frames.payload.bit_depth, next_depth)
        m.d.comb += take.eq(do_pulse & new_frame & (p == 0) & self.frames.valid & frame_ok & ~use_prng)
        with m.If(take):
            m.d.comb += self.frames.ready.eq(1)
        with m.If(do_pulse):
            with m.If(_diff(pulse_at[p], now) < 0):
                m.d.sync += self.status.late.eq(self.status.late + 1)
            m.d.sync += [
                writable[p].eq(now + regs.t_rst + regs.t_settle),
                rst_free[p].eq(now + regs.t_rst),
                rst_any.eq(now + regs.t_rst),
                loaded[p].eq(0),
                pulse_at[p].eq(now + Mux(pdark, regs.dark_gap, plane_len)),
            ]
            with m.If(p == 0):
                m.d.sync += [next_slot.eq(n_slot), next_depth.eq(n_depth)]
            m.d.comb += [queue.w_en.eq(1), enq.group.eq(p), enq.slot.eq(slot[p]),
                         enq.depth.eq(pdepth), enq.pos.eq(pj + 1)]
            with m.If(pdark | hidden):
                m.d.sync += [dark[p].eq(0), pos[p].eq(Mux(last, 0, pj + 1))]
                with m.If(last):
                    m.d.sync += [slot[p].eq(n_slot), depth[p].eq(n_depth)]
                    m.d.comb += [enq.slot.eq(n_slot), enq.depth.eq(n_depth), enq.pos.eq(0)]
                    with m.If(pdark & ~regs.chain):
                        m.d.sync += pending[p].eq(0)
            with m.Else():
                m.d.sync += dark[p].eq(1)
                m.d.comb += enq.clear.eq(1)
            # frame boundaries: sync out, camera trigger, counter
            with m.If((p == 0) & ~pdark & (pj == 0)):
                m.d.sync += [self.sync_out.eq(1), self.status.frames.eq(self.status.frames + 1)]
            with m.If((p == n_groups - 1) & pdark & last & ~regs.chain):
                m.d.sync += self.sync_out.eq(0)

        cam_at = Signal(TIME_BITS)
        cam_armed = Signal()
        with m.If(do_pulse & (p == 0) & ~pdark & (pj == 0)):
            m.d.sync += [cam_at.eq(now + regs.camera_offset), cam_armed.eq(1)]
        with m.Elif(cam_armed & (_diff(now, cam_at + regs.camera_width) >= 0)):
            m.d.sync += cam_armed.eq(0)
        # registered like the command pins: the pulse leaves ``camera_offset`` after the frame's
        # first clocking pulse leaves
        m.d.sync += self.camera_out.eq(cam_armed & (_diff(now, cam_at) >= 0)
                                       & (_diff(now, cam_at + regs.camera_width) < 0))

        # ---- start: take the first frame, queue every group's first plane ----
        all_ready = Cat(~active[g] | (~pending[g] & loaded[g]) for g in range(GMAX)).all()
        playing = Cat(active[g] & pending[g] for g in range(GMAX)).any()
        flush_until = Signal(TIME_BITS)
        flush_cycles = Signal(DURATION_BITS)
        m.d.comb += flush_cycles.eq(flush_rows(dmd) * regs.row_period)
        start_group = Signal(grp_bits + 1)
        with m.FSM(name="start") as start_fsm:
            with m.State("WAIT"):
                with m.If(init.running & (self.frames.valid & frame_ok | use_prng)):
                    m.d.comb += self.frames.ready.eq(~use_prng)
                    f_slot = Mux(use_prng, 0, self.frames.payload.slot)
                    f_depth = Mux(use_prng, 1, self.frames.payload.bit_depth)
                    m.d.sync += [next_slot.eq(f_slot), next_depth.eq(f_depth)]
                    for g in range(GMAX):
                        m.d.sync += [slot[g].eq(f_slot), depth[g].eq(f_depth),
                                     pos[g].eq(0), dark[g].eq(0)]
                    m.next = "QUEUE"
            def queue_first_planes():
                m.d.comb += [queue.w_en.eq(1), enq.group.eq(start_group), enq.slot.eq(next_slot),
                             enq.depth.eq(next_depth), enq.pos.eq(0)]
                m.d.sync += start_group.eq(start_group + 1)
                with m.If(start_group == n_groups - 1):
                    m.next = "RUN"
            with m.State("QUEUE"):
                queue_first_planes()
            with m.State("RUN"):
                m.d.comb += running.eq(1)
                with m.If(take_idle):
                    m.next = "RELOAD"
                    with m.If(~all_ready):
                        m.next = "FLUSH"
            with m.State("FLUSH"):
                # the stale loads are dropped: queued ones by the requester, looked-up ones
                # here, and the words already asked for are discarded; then the newer frame's
                # first planes are queued, exactly ``flush_cycles`` after it was taken
                m.d.comb += [running.eq(1), flushing.eq(1)]
                drained = requester.ongoing("IDLE") & ~queue.r_rdy & ~loads.r_rdy & (owed == 0)
                with m.If(drained & (_diff(flush_until, now) <= 0)):
                    m.next = "RELOAD"
            with m.State("RELOAD"):
                m.d.comb += running.eq(1)
                queue_first_planes()

        # ---- triggers ----
        # a newer frame offered while no group plays: it replaces the preloaded first planes
        # (the loads wait for the store's first words); any stale load still in flight is
        # abandoned: the row cycle on the bus ends, nothing of it is pulsed (no trigger is obeyed
        # before every group is loaded again), and the settle times of the last pulses still hold.
        # With ``reload`` at rest, the same frame is loaded again under new registers.
        newer = ~use_prng & ~regs.chain & self.frames.valid & frame_ok
        idle = start_fsm.ongoing("RUN") & ~playing
        resting = start_fsm.ongoing("RUN") & all_ready
        m.d.comb += [take_idle.eq((idle & newer) | (resting & self.reload)),
                     self.at_rest.eq(start_fsm.ongoing("WAIT") | resting)]
        with m.If(take_idle & newer):
            m.d.comb += self.frames.ready.eq(1)
        with m.If(take_idle):
            wait = Mux(all_ready, 0, flush_cycles)
            lead = now + regs.reload_lead + wait
            r_slot = Mux(newer, self.frames.payload.slot, next_slot)
            r_depth = Mux(newer, self.frames.payload.bit_depth, next_depth)
            m.d.sync += [next_slot.eq(r_slot), next_depth.eq(r_depth),
                         start_group.eq(0), flush_until.eq(now + wait), fresh.eq(1), finishing.eq(0)]
            for g in range(GMAX):
                m.d.sync += [slot[g].eq(r_slot), depth[g].eq(r_depth),
                             loaded[g].eq(0), writable[g].eq(Mux(_diff(writable[g], lead) < 0, lead, writable[g]))]
        with m.If(trig.strobe):
            with m.If(~running):
                m.d.sync += self.status.early.eq(self.status.early + 1)
            with m.Elif(all_ready & ~take_idle):
                start = (now + 2) & ~1
                m.d.sync += self.status.triggers.eq(self.status.triggers + 1)
                for g in range(GMAX):
                    with m.If(active[g]):
                        m.d.sync += [pending[g].eq(1), pulse_at[g].eq(start + regs.stagger * g)]
            with m.Else():
                m.d.sync += self.status.overruns.eq(self.status.overruns + 1)

        # ---- pins ----
        toggle = Signal()
        m.d.sync += toggle.eq(~toggle)
        pins = self.pins
        m.d.comb += [pins.arstz.eq(1), pins.wdt_enblz.eq(1), pins.comp_data.eq(0),
                     pins.ns_flip.eq(regs.ns_flip), pins.pwr_float.eq(regs.park)]
        with m.If(init.training):
            # the four edges of the pattern over two cycles; DVALID (one bit per cycle in the
            # core) carries the falling-edge bits, the platform layer's DDR output the rest
            rise = Mux(toggle, TRAINING_EDGES[2], TRAINING_EDGES[0])
            fall = Mux(toggle, TRAINING_EDGES[3], TRAINING_EDGES[1])
            for bus in "abcd"[:dmd.buses]:
                m.d.comb += [getattr(pins, f"din_{bus}").rise.eq(rise.replicate(16)),
                             getattr(pins, f"din_{bus}").fall.eq(fall.replicate(16))]
            m.d.comb += [pins.dvalid.eq(fall), pins.rst2blkz.eq(1)]
        with m.Else():
            for bus, edge, lsb in beat_lanes(dmd.buses):
                m.d.comb += getattr(getattr(pins, f"din_{bus.lower()}"), edge).eq(word[lsb:lsb + 16])
            m.d.comb += [pins.dvalid.eq(dvalid), pins.rowmd.eq(cmd.rowmd), pins.rowad.eq(cmd.rowad),
                         pins.blkmd.eq(cmd.blkmd), pins.blkad.eq(cmd.blkad),
                         pins.rst2blkz.eq(cmd.rst2blkz)]
        return m
