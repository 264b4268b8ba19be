"""The bit-plane store (slots, writer, reader) with the serialiser in front and the MCB model
behind, in the Amaranth simulator, against numpy: the layout and traffic on the test geometry,
the slot policy (which slot, which frame, which counter; nothing there depends on the size of a
frame) on its short variant; the frame broker's occupancy maps against a model store."""

import random

import numpy as np
import pytest

from gateware.store.slots import SlotCounters
from sim.harness.amaranth_sim import simulate, stream_collect, stream_feed
from sim.models import bitplane_model as bitplane
from sim.models import store_stim
from sim.models.mcb_model import McbModel, McbTiming, amaranth_process, widths
from sim.models.store_stim import SHORT_DMD
from sim.tb.store_chain import StoreChain
from spec.facts import TEST_DMD

DMD = TEST_DMD
SYNC_HZ, DMD_HZ = 125e6, 200e6
#: Row numbers the short geometry's row field holds (rows 24 to 31 lie beyond the frame).
FIELD_ROWS = 1 << (SHORT_DMD.rows - 1).bit_length()


class Bench:
    """A StoreChain with the MCB model on both ports and sequencer-side helpers (``dmd``)."""

    def __init__(self, dmd=DMD, *, slots=4, timing=None, read_width=128, **store):
        self.dmd, self.slots, self.read_width = dmd, slots, read_width
        self.dut = StoreChain(dmd, slots=slots, read_width=read_width, **store)
        self.model = McbModel(64 * 1024, timing=timing, widths=widths(self.dut.mcb_write, self.dut.mcb_read))
        self.processes = [
            amaranth_process(self.model.ports[0], self.dut.mcb_write, domain="sync", frequency=SYNC_HZ),
            amaranth_process(self.model.ports[1], self.dut.mcb_read, domain="dmd", frequency=DMD_HZ),
        ]

    def run(self, testbenches, name, deadline=3e-4):
        simulate(self.dut, testbenches, name=name, clocks={"sync": SYNC_HZ, "dmd": DMD_HZ},
                 processes=self.processes, deadline=deadline)

    async def settle(self, ctx):
        """Wait until the store has done all it will with the pixels it took: its memory port
        calibrated and idle for longer than the last row can take to reach it (a slot's clear,
        one row per cycle, and the row's words)."""
        port, quiet = self.model.ports[0], 0
        while quiet < self.dmd.rows + 64:
            await ctx.tick()
            quiet = quiet + 1 if port.outputs["calib_done"] and port.idle() else 0

    async def feed(self, ctx, image, frame_id, rows=None, idle=0.0, base=0, carried=0):
        await stream_feed(ctx, self.dut.pixels, store_stim.frame_beats(image, frame_id, rows=rows, base=base,
                                                                        carried=carried), idle=idle)

    async def feed_sequence(self, ctx, images, order, depth=1):
        """Sequence mode of ``len(images)`` frames at ``depth``, then the frames in ``order``."""
        ctx.set(self.dut.sequence_length, len(images))
        ctx.set(self.dut.bit_depth, depth)
        for _ in range(3):
            await ctx.tick()
        for f in order:
            await self.feed(ctx, images[f], f)

    async def ask(self, ctx):
        """Ask for a frame and wait for the answer: (slot, frame_id, bit_depth)."""
        dut = self.dut
        ctx.set(dut.ask.valid, 1)
        await ctx.tick("dmd").until(dut.ask.ready)
        ctx.set(dut.ask.valid, 0)
        ctx.set(dut.frames.ready, 1)
        payload, = await ctx.tick("dmd").sample(dut.frames.payload).until(dut.frames.valid)
        ctx.set(dut.frames.ready, 0)
        return int(payload.slot), int(payload.frame_id), int(payload.bit_depth)

    async def write_entries(self, ctx, table, *, loop=0):
        """Write ``table`` (dicts of :class:`~gateware.store.entries.Entry`'s fields) to the entry
        table, entry ``k`` at index ``k``, and play it (``loop`` or once)."""
        for index, entry in enumerate(table):
            ctx.set(self.dut.entry_writes.payload, {"index": index, **entry})
            ctx.set(self.dut.entry_writes.valid, 1)
            await ctx.tick()
        ctx.set(self.dut.entry_writes.valid, 0)
        ctx.set(self.dut.entries, len(table))
        ctx.set(self.dut.loop, loop)

    async def answer(self, ctx, wait=None):
        """Ask for a frame: the answer's payload, or None if none comes in ``wait`` cycles."""
        dut = self.dut
        ctx.set(dut.ask.valid, 1)
        ctx.set(dut.frames.ready, 1)
        for _ in range(wait or 100_000):
            _, _, asked, valid, payload = await ctx.tick("dmd").sample(dut.ask.ready, dut.frames.valid,
                                                                       dut.frames.payload)
            if asked:
                ctx.set(dut.ask.valid, 0)
            if valid:
                ctx.set(dut.frames.ready, 0)
                return payload
        ctx.set(dut.ask.valid, 0)
        ctx.set(dut.frames.ready, 0)
        return None

    async def release(self, ctx, slot):
        ctx.set(self.dut.release.payload, slot)
        ctx.set(self.dut.release.valid, 1)
        await ctx.tick("dmd").until(self.dut.release.ready)
        ctx.set(self.dut.release.valid, 0)

    async def read(self, ctx, slot, plane, first_row=0, row_count=None, stall=0.0, rng=None):
        dut = self.dut
        row_count = self.dmd.rows if row_count is None else row_count
        ctx.set(dut.requests.payload, {"slot": slot, "plane": plane, "first_row": first_row,
                                       "row_count": row_count})
        ctx.set(dut.requests.valid, 1)
        await ctx.tick("dmd").until(dut.requests.ready)
        ctx.set(dut.requests.valid, 0)
        transfers = []
        while len(transfers) < row_count * self.dmd.words_per_row * 64 // self.read_width:
            ready = not (stall and rng.random() < stall)
            ctx.set(dut.planes.ready, ready)
            _, _, valid, payload = await ctx.tick("dmd").sample(dut.planes.valid, dut.planes.payload)
            if valid and ready:
                transfers.append(payload)
        ctx.set(dut.planes.ready, 0)
        return store_stim.plane_words(transfers, self.read_width)

    async def occupancy(self, ctx, slot):
        got = []
        for block in range(self.dmd.blocks):
            ctx.set(self.dut.occupancy.slot, slot)
            ctx.set(self.dut.occupancy.block, block)
            await ctx.tick("dmd")
            await ctx.tick("dmd")
            got.append(ctx.get(self.dut.occupancy.planes))
        return got

    async def check_frame(self, ctx, slot, image, depth, what="", stall=0.0):
        rng = random.Random(slot)
        for plane in store_stim.stored_planes(depth):
            words = await self.read(ctx, slot, plane, stall=stall, rng=rng)
            store_stim.check_plane(self.dmd, image, plane, words, what=what)
        store_stim.check_occupancy(self.dmd, image, depth, await self.occupancy(ctx, slot), what=what)

    async def receive(self, ctx, image, frame_id, what=""):
        """Ask for a frame: it must be ``frame_id``, and read back as ``image``. Its slot."""
        slot, got, depth = await self.ask(ctx)
        assert got == frame_id, f"frame {got} given, not {frame_id}"
        await self.check_frame(ctx, slot, image, depth, what=what or f"frame {frame_id}")
        return slot

    async def recovered(self, ctx, frames_lost):
        """Wait (``dmd``) until the store is whole again after the memory's one calibration
        loss, and check that it counted that loss and ``frames_lost`` frames forgotten."""
        await ctx.tick("dmd").until(~self.dut.lost)
        counters = self.counters(ctx)
        assert counters["calibration_losses"] == 1 and counters["frames_lost"] == frames_lost, counters
        assert self.model.calib_losses == 1

    def counters(self, ctx):
        c = ctx.get(self.dut.counters)
        return {name: int(getattr(c, name)) for name, _ in SlotCounters.as_shape()}


async def wait_until(ctx, flag, domain="sync"):
    while not flag():
        await ctx.tick(domain)


def play_one_by_one(bench, frames, *, consumer_stall=0.0, idle=0.0):
    """frames: [(image, frame_id, depth)]; each is sent, then shown, read back and released."""
    dut = bench.dut
    shown = []
    state = {"next": 0}

    async def producer(ctx):
        for i, (image, frame_id, depth) in enumerate(frames):
            await wait_until(ctx, lambda i=i: state["next"] == i)
            ctx.set(dut.bit_depth, depth)
            await bench.feed(ctx, image, frame_id, idle=idle)

    async def consumer(ctx):
        for i, (image, frame_id, depth) in enumerate(frames):
            slot, got_id, got_depth = await bench.ask(ctx)
            assert (got_id, got_depth) == (frame_id, depth)
            await bench.check_frame(ctx, slot, image, depth, what=f"frame {frame_id}", stall=consumer_stall)
            await bench.release(ctx, slot)
            shown.append(got_id)
            state["next"] = i + 1

    return producer, consumer, shown


def test_bit_depths(test_name):
    """Random images at bit depths 8 and 1 (every depth runs in the Verilog test): every stored
    plane reads back as numpy slices it. Rows in order go out in bursts of 32 words (16 rows)."""
    bench = Bench()
    frames = [(store_stim.random_image(DMD, d), 100 + i, d) for i, d in enumerate((8, 1))]
    producer, consumer, shown = play_one_by_one(bench, frames, consumer_stall=0.3, idle=0.1)
    bench.run([producer, consumer], test_name)
    assert shown == [f for _, f, _ in frames]
    bursts = [words for _instr, words, _address in bench.model.ports[0].command_log]
    assert max(bursts) == 32 and len(bursts) == (8 + 1) * DMD.rows // 16


def test_rows_in_any_order(test_name):
    """Rows shuffled: bursts break where rows stop following each other; the frame still reads
    back whole."""
    bench = Bench()
    dut = bench.dut
    image = store_stim.random_image(DMD, 12)
    order = list(range(DMD.rows))
    random.Random(3).shuffle(order)
    order[10:10] = [40, 41, 42]                          # a run that can share bursts
    order = [r for i, r in enumerate(order) if r not in order[:i]]

    async def producer(ctx):
        ctx.set(dut.bit_depth, 2)
        await bench.feed(ctx, image, 1, rows=order)

    async def consumer(ctx):
        slot, _, depth = await bench.ask(ctx)
        await bench.check_frame(ctx, slot, image, depth, what="shuffled")

    bench.run([producer, consumer], test_name)
    bursts = [words for _instr, words, _address in bench.model.ports[0].command_log]
    assert 2 * DMD.words_per_row in bursts and sum(bursts) == 2 * DMD.rows * DMD.words_per_row


def test_stalled_memory(test_name):
    """A slow memory with long, frequent refreshes and random stalls: full FIFOs on both sides,
    nothing lost, nothing corrupted."""
    timing = McbTiming(efficiency=0.08, refresh_interval_s=1.0e-6, refresh_s=300e-9,
                       read_latency_s=200e-9, calib_delay_s=3e-6, stall_chance=0.3, stall_max_s=400e-9)
    bench = Bench(timing=timing)
    frames = [(store_stim.random_image(DMD, 50), 1, 3)]
    producer, consumer, shown = play_one_by_one(bench, frames, consumer_stall=0.5)
    bench.run([producer, consumer], test_name, deadline=2e-3)
    assert shown == [1]
    assert bench.model.refreshes > 10


def test_fast_producer_slow_consumer(test_name):
    """Frames arrive while the sequencer holds one: when it asks again it gets the newest
    complete frame, the ones in between are replaced (counted), and what it gets reads back whole."""
    bench = Bench(SHORT_DMD)
    dut = bench.dut
    images = {f: store_stim.random_image(SHORT_DMD, 200 + f) for f in range(1, 5)}
    got, sent = [], []

    async def producer(ctx):
        ctx.set(dut.bit_depth, 1)
        for f, image in images.items():
            await bench.feed(ctx, image, f)
        await bench.settle(ctx)
        sent.append(True)

    async def consumer(ctx):
        slot, f, depth = await bench.ask(ctx)
        got.append(f)
        await wait_until(ctx, lambda: sent, domain="dmd")      # a slow consumer: shows 1 throughout
        await bench.release(ctx, slot)
        slot, f, depth = await bench.ask(ctx)
        got.append(f)
        await bench.check_frame(ctx, slot, images[f], depth, what=f"frame {f}")
        counters = bench.counters(ctx)
        assert counters["frames_complete"] == 4
        assert counters["frames_replaced"] == 2
        assert counters["frames_abandoned"] == 0

    bench.run([producer, consumer], test_name, deadline=6e-4)
    assert got == [1, 4]


def test_slow_producer_fast_consumer(test_name):
    """The consumer keeps an ask outstanding: it gets every frame, in order, none replaced."""
    bench = Bench(SHORT_DMD)
    dut = bench.dut
    images = {f: store_stim.random_image(SHORT_DMD, 300 + f) for f in (65535, 0, 1)}  # id wraps
    got = []

    async def producer(ctx):
        ctx.set(dut.bit_depth, 1)
        for f, image in images.items():
            await bench.feed(ctx, image, f, idle=0.5)

    async def consumer(ctx):
        held = None
        for _ in images:
            slot, f, depth = await bench.ask(ctx)
            got.append(f)
            if held is not None:
                await bench.release(ctx, held)
            await bench.check_frame(ctx, slot, images[f], depth, what=f"frame {f}")
            held = slot
        counters = bench.counters(ctx)
        assert counters["frames_replaced"] == 0 and counters["rows_stale"] == 0

    bench.run([producer, consumer], test_name, deadline=6e-4)
    assert got == list(images)


def test_missing_row_never_shown(test_name):
    """A frame with one row missing is never given out; the next complete one is, and the
    incomplete one is counted as abandoned."""
    bench = Bench(SHORT_DMD)
    dut = bench.dut
    incomplete = store_stim.random_image(SHORT_DMD, 1)
    complete = store_stim.random_image(SHORT_DMD, 2)
    got = []

    async def producer(ctx):
        ctx.set(dut.bit_depth, 2)
        await bench.feed(ctx, incomplete, 10, rows=[r for r in range(SHORT_DMD.rows) if r != 13])
        await bench.settle(ctx)                      # the consumer's ask waits throughout
        await bench.feed(ctx, complete, 11)

    async def consumer(ctx):
        slot, f, depth = await bench.ask(ctx)
        got.append(f)
        await bench.check_frame(ctx, slot, complete, depth)
        counters = bench.counters(ctx)
        assert counters["frames_abandoned"] == 1 and counters["frames_complete"] == 1

    bench.run([producer, consumer], test_name)
    assert got == [11]


def test_shown_slot_never_written_and_hostile_headers(test_name):
    """While frame 20 is shown: records with its id are refused, rows beyond the frame and
    duplicated rows are refused, each counted; no word lands outside the receiving slots; the
    shown frame reads back unchanged at the end."""
    bench = Bench(SHORT_DMD)
    dut = bench.dut
    amap_slots = bench.slots
    first = store_stim.random_image(SHORT_DMD, 5)
    second = store_stim.random_image(SHORT_DMD, 6)
    hostile = store_stim.random_image(SHORT_DMD, 7)
    beyond = np.zeros((FIELD_ROWS, SHORT_DMD.columns), np.uint8)
    phase = {"shown": None}

    async def producer(ctx):
        ctx.set(dut.bit_depth, 1)
        await bench.feed(ctx, first, 20)
        await wait_until(ctx, lambda: phase["shown"] is not None)
        since = len(bench.model.write_log)
        await bench.feed(ctx, hostile, 20, rows=range(0, 10))                       # shown frame id
        await bench.feed(ctx, beyond, 21, rows=range(SHORT_DMD.rows, FIELD_ROWS))   # rows outside
        order = list(range(SHORT_DMD.rows))
        order[12:12] = [3, 4, 20]                                                   # overlapping
        await bench.feed(ctx, second, 21, rows=order)
        await bench.feed(ctx, hostile, 19, rows=range(0, 2))                        # stale frame id
        phase["since"] = since

    async def consumer(ctx):
        slot, f, _ = await bench.ask(ctx)
        assert f == 20
        phase["shown"] = slot
        slot2, f2, depth = await bench.ask(ctx)
        assert f2 == 21
        await bench.check_frame(ctx, slot2, second, depth, what="frame 21")
        await wait_until(ctx, lambda: "since" in phase, domain="dmd")
        for _ in range(200):
            await ctx.tick("dmd")
        await bench.check_frame(ctx, slot, first, 1, what="shown frame 20")
        counters = bench.counters(ctx)
        assert counters["rows_shown"] == 10
        assert counters["rows_outside"] == FIELD_ROWS - SHORT_DMD.rows
        assert counters["rows_duplicate"] == 3
        assert counters["rows_stale"] == 2
        store_stim.check_writes_inside(bench.model, SHORT_DMD, amap_slots,
                                       set(range(amap_slots)) - {slot}, since=phase["since"])

    bench.run([producer, consumer], test_name, deadline=6e-4)


def test_sequence_mode(test_name):
    """Sequence of 3 frames sent out of order: played 0, 1, 2, 0, 1, 2, 0 with their ids."""
    bench = Bench(SHORT_DMD)
    images = {f: store_stim.random_image(SHORT_DMD, 400 + f) for f in range(3)}
    got = []

    async def producer(ctx):
        await bench.feed_sequence(ctx, images, (2, 0, 1))
        await bench.feed(ctx, images[1], 3, rows=range(4))        # beyond the sequence: stale

    async def consumer(ctx):
        held = None
        for _ in range(7):
            slot, f, depth = await bench.ask(ctx)
            assert slot == f and depth == 1
            got.append(f)
            if held is not None:
                await bench.release(ctx, held)
            held = slot
            if len(got) <= 3:
                await bench.check_frame(ctx, slot, images[f], depth, what=f"sequence frame {f}")
        counters = bench.counters(ctx)
        assert counters["frames_complete"] == 3 and counters["frames_replaced"] == 0
        assert counters["rows_stale"] == 4

    bench.run([producer, consumer], test_name, deadline=6e-4)
    assert got == [0, 1, 2, 0, 1, 2, 0]


def test_sequence_of_two_asked_ahead(test_name):
    """Sequence of 2 frames, the next frame asked for before the shown one is handed back (as
    the broker does when the sequencer takes the frame on offer): the ask for the slot still
    shown waits, its release is taken meanwhile, and the frames play 0, 1, 0, 1, 0."""
    bench = Bench(SHORT_DMD)
    dut = bench.dut
    images = {f: store_stim.random_image(SHORT_DMD, 900 + f) for f in range(2)}
    got = []

    async def producer(ctx):
        await bench.feed_sequence(ctx, images, (0, 1))

    async def consumer(ctx):
        # the sequencer shows one frame while the broker holds the next on offer
        shown, f, _ = await bench.ask(ctx)
        got.append(f)
        offered, f, _ = await bench.ask(ctx)
        got.append(f)
        for _ in range(3):
            # the offered frame is taken: the broker asks again at once, for the slot still
            # shown; that slot's release follows later
            ctx.set(dut.ask.valid, 1)
            await ctx.tick("dmd").until(dut.ask.ready)
            ctx.set(dut.ask.valid, 0)
            for _ in range(20):
                await ctx.tick("dmd")
            await bench.release(ctx, shown)
            shown = offered
            ctx.set(dut.frames.ready, 1)
            payload, = await ctx.tick("dmd").sample(dut.frames.payload).until(dut.frames.valid)
            ctx.set(dut.frames.ready, 0)
            offered = int(payload.slot)
            got.append(int(payload.frame_id))
        assert bench.counters(ctx)["bad_releases"] == 0

    bench.run([producer, consumer], test_name, deadline=6e-4)
    assert got == [0, 1, 0, 1, 0]


@pytest.mark.parametrize("read_width", [128, 64])
def test_row_subsets_and_bad_requests(read_width, test_name):
    """Runs of rows of a plane read back as numpy's slices, through a reader of either width;
    requests past the frame are dropped and counted, and produce no words."""
    bench = Bench(read_width=read_width)
    dut = bench.dut
    image = store_stim.random_image(DMD, 9)

    async def producer(ctx):
        ctx.set(dut.bit_depth, 8)
        await bench.feed(ctx, image, 1)

    async def consumer(ctx):
        slot, _, _ = await bench.ask(ctx)
        for bad in ({"slot": slot, "plane": 0, "first_row": 90, "row_count": 7},
                    {"slot": slot, "plane": 0, "first_row": 0, "row_count": 0},
                    {"slot": 9, "plane": 0, "first_row": 0, "row_count": 1}):
            ctx.set(dut.requests.payload, bad)
            ctx.set(dut.requests.valid, 1)
            await ctx.tick("dmd").until(dut.requests.ready)
        ctx.set(dut.requests.valid, 0)
        for plane, first, count in ((7, 0, 1), (3, 24, 24), (0, 95, 1), (5, 10, 80)):
            words = await bench.read(ctx, slot, plane, first, count)
            store_stim.check_plane(DMD, image, plane, words, first, count)
        assert ctx.get(dut.bad_requests) == 3
        assert not ctx.get(dut.planes.valid)

    bench.run([producer, consumer], test_name)


def test_no_free_slot_and_bad_release(test_name):
    """Three slots, the sequencer holding two: a complete frame waits in the third; a newer
    frame finds no slot and is refused row by row (counted), the waiting one is still given;
    releasing a slot that is not shown is counted and changes nothing."""
    bench = Bench(SHORT_DMD, slots=3)
    dut = bench.dut
    images = {f: store_stim.random_image(SHORT_DMD, 600 + f) for f in range(1, 5)}
    phase = {}

    async def producer(ctx):
        ctx.set(dut.bit_depth, 1)
        for f in (1, 2):
            await bench.feed(ctx, images[f], f)
            await wait_until(ctx, lambda f=f: phase.get("held") == f)
        await bench.feed(ctx, images[3], 3)
        await bench.feed(ctx, images[4], 4)
        phase["sent"] = True

    async def consumer(ctx):
        held = []
        for f in (1, 2):
            slot, got, _ = await bench.ask(ctx)
            assert got == f
            held.append(slot)
            phase["held"] = f
        await wait_until(ctx, lambda: "sent" in phase, domain="dmd")
        for _ in range(100):
            await ctx.tick("dmd")
        counters = bench.counters(ctx)
        assert counters["rows_no_slot"] == SHORT_DMD.rows and counters["frames_complete"] == 3
        ready_slot = ({0, 1, 2} - set(held)).pop()
        await bench.release(ctx, ready_slot)                 # not shown: refused
        for _ in range(20):
            await ctx.tick("dmd")
        assert bench.counters(ctx)["bad_releases"] == 1
        await bench.release(ctx, held[0])
        slot, got, depth = await bench.ask(ctx)
        assert (slot, got) == (ready_slot, 3)
        await bench.check_frame(ctx, slot, images[3], depth, what="frame 3")

    bench.run([producer, consumer], test_name)


def test_read_rate_under_ingest_is_the_plans():
    """The benchmark's plane read on the DLP7000 geometry, through the 128-bit port while the writer
    takes rows at the GigE line rate: the reader gets from the MCB model the rate the system run's
    plan counts on (``sim.rigs.fast_system_rig.read_rate``, the model's bandwidth less the ingest)
    within 1 %, so the look-ahead hides the latency and the plan's row period is the shortest the
    memory keeps fed (the figures are printed by ``python -m sim.bench.store_figures``)."""
    from sim.bench.store_figures import read_rate, row_period
    from sim.rigs import xga_run as xga
    from sim.rigs.fast_system_rig import INGEST_BYTES_PER_S
    from sim.rigs.fast_system_rig import read_rate as planned_rate
    figure = read_rate(timing=McbTiming(), ingest_bytes_per_s=INGEST_BYTES_PER_S)
    assert figure["ingest_bytes_per_s"] == pytest.approx(INGEST_BYTES_PER_S, rel=0.01), "the writer kept up"
    assert figure["words_per_cycle"] == pytest.approx(planned_rate(McbTiming(), xga.DMD_HZ), rel=0.01)
    assert xga.plan().params.row_period == row_period(xga.DMD, figure["words_per_cycle"])


def test_random_events_against_policy_model(seed, test_name):
    """Random records (new frames, parts and rests of frames, stale and shown ids, rows beyond the
    frame, overlaps), asks and releases, a fresh seed each run: after each event the gateware's
    counters and the frames it gives equal the reference model's (sim.models.slots_model)."""
    from sim.models.slots_model import SlotPolicy

    rng = random.Random(seed)
    bench = Bench(SHORT_DMD, slots=4)
    dut = bench.dut
    rows = SHORT_DMD.rows
    policy = SlotPolicy(rows, 4)
    image = store_stim.random_image(SHORT_DMD, 77)
    tall = np.vstack([image, image[:FIELD_ROWS - rows]])        # rows beyond the frame, for hostile records
    held = {}                                                   # gateware slot -> frame id
    checked = {"events": 0}
    state = {"turn": "producer", "event": None}
    newest = 1

    # first, every outcome once for certain (replaced, abandoned, outside, stale, duplicate,
    # shown), then random events
    events = [("rows", 2, list(range(rows))), ("rows", 3, list(range(rows))),
              ("rows", 4, [0, 1, 2]), ("rows", 5, list(range(rows))), ("rows", 5, [rows - 1, rows, rows + 1]),
              ("rows", 2, [0]), ("rows", 6, [0, 1]), ("rows", 6, [1, 2]), ("ask", None, None), ("shown", None, [3])]
    newest = 6
    for _ in range(44):
        kind = rng.choice(["full", "newpart", "part", "part", "rest", "old", "beyond", "ask", "ask",
                           "release", "shown"])
        if kind == "full":
            newest += rng.choice([1, 1, 2])
            events.append(("rows", newest, list(range(rows))))
        elif kind == "newpart":
            newest += 1
            events.append(("rows", newest, list(range(rng.randrange(rows // 2), rows * 2 // 3))))
        elif kind == "part":
            first = rng.randrange(rows)
            events.append(("rows", newest, list(range(first, min(rows, first + rng.randrange(1, rows // 3))))))
        elif kind == "rest":
            events.append(("rest", newest, None))
        elif kind == "old":
            events.append(("rows", newest - rng.randrange(1, 4), list(range(rng.randrange(rows // 12), rows // 8))))
        elif kind == "beyond":
            events.append(("rows", newest, list(range(rows - 2, rng.randrange(rows + 1, FIELD_ROWS + 1)))))
        elif kind == "shown":
            events.append(("shown", None, [rng.randrange(rows)]))
        else:
            events.append((kind, None, None))
    # then for certain: overlapping records, and a sequencer holding three of the four slots
    n = newest
    events += [("release_all", None, None), ("rows", n + 1, list(range(rows // 5))),
               ("rows", n + 1, list(range(rows // 10, rows * 3 // 10)))]
    for k in range(2, 5):
        events += [("rows", n + k, list(range(rows))), ("ask", None, None)]
    events += [("shown", None, [0]), ("rows", n + 5, list(range(rows))), ("rows", n + 6, list(range(4)))]

    async def producer(ctx):
        ctx.set(dut.bit_depth, 1)
        for kind, frame, record in events:
            if kind == "rest":
                have = policy.frames.get(frame, {"rows": set()})["rows"]
                kind, record = "rows", [r for r in range(rows) if r not in have]
            if kind == "shown":
                # a row of a frame the sequencer holds (none: no row)
                shown = policy.in_state("SHOWN")
                kind, frame, record = "rows", (shown[0] if shown else newest), (record if shown else [])
            if kind == "rows":
                for row in record:
                    policy.row(frame & 0xFFFF, row, 1)
                await bench.feed(ctx, tall, frame & 0xFFFF, rows=record)
                await bench.settle(ctx)
            else:
                state["event"] = kind
                state["turn"] = "consumer"
                await wait_until(ctx, lambda: state["turn"] == "producer")
            assert bench.counters(ctx) == policy.counters, f"after {kind} {frame}"
            checked["events"] += 1
        state["turn"] = "done"

    async def consumer(ctx):
        while True:
            await wait_until(ctx, lambda: state["turn"] != "producer", domain="dmd")
            if state["turn"] == "done":
                return
            if state["event"] == "ask" and policy.can_answer():
                want = policy.ask()
                slot, frame, _ = await bench.ask(ctx)
                assert frame == want
                held[slot] = frame
                if len(held) == 1:
                    words = await bench.read(ctx, slot, 7, 0, 8)
                    store_stim.check_plane(SHORT_DMD, image, 7, words, 0, 8, what=f"frame {frame}")
            elif state["event"] in ("release", "release_all") and held:
                for slot in ([rng.choice(sorted(held))] if state["event"] == "release" else sorted(held)):
                    policy.release(held.pop(slot))
                    await bench.release(ctx, slot)
                for _ in range(20):
                    await ctx.tick("dmd")
            state["turn"] = "producer"

    bench.run([producer, consumer], test_name, deadline=3e-3)
    assert checked["events"] == len(events)
    exercised = {name for name, value in policy.counters.items() if value}
    # (a lost memory: test_calibration_loss_forgets_every_frame; deltas: test_delta_frames;
    # sequence entries: test_sequence_entries)
    assert exercised >= set(policy.counters) - {"bad_releases", "calibration_losses", "frames_lost",
                                                "rows_no_base", "entries_skipped"}, policy.counters


def test_mode_change_keeps_the_shown_frame(test_name):
    """Streaming, then sequence mode while a streamed frame is shown: that slot is kept (records
    for it are refused) until released, then the sequence loads and plays in order."""
    bench = Bench(SHORT_DMD)
    dut = bench.dut
    streamed = store_stim.random_image(SHORT_DMD, 800)
    images = {f: store_stim.random_image(SHORT_DMD, 810 + f) for f in range(2)}
    phase = {}

    async def producer(ctx):
        ctx.set(dut.bit_depth, 1)
        await bench.feed(ctx, streamed, 5)
        await wait_until(ctx, lambda: "shown" in phase)
        ctx.set(dut.sequence_length, 2)
        for _ in range(4):
            await ctx.tick()
        shown = phase["shown"]
        await bench.feed(ctx, images[shown], shown, rows=range(3))     # its slot is shown: refused
        await bench.feed(ctx, images[1 - shown], 1 - shown)
        phase["refused"] = True
        await wait_until(ctx, lambda: "released" in phase)
        await bench.feed(ctx, images[shown], shown)

    async def consumer(ctx):
        slot, f, depth = await bench.ask(ctx)
        assert f == 5 and slot in (0, 1)
        phase["shown"] = slot
        await wait_until(ctx, lambda: "refused" in phase, domain="dmd")
        for _ in range(50):
            await ctx.tick("dmd")
        assert bench.counters(ctx)["rows_shown"] == 3
        await bench.check_frame(ctx, slot, streamed, depth, what="streamed frame kept")
        await bench.release(ctx, slot)
        phase["released"] = True
        got = []
        held = None
        for _ in range(3):
            slot, f, depth = await bench.ask(ctx)
            got.append(f)
            if held is not None:
                await bench.release(ctx, held)
            held = slot
        assert got == [0, 1, 0]
        await bench.check_frame(ctx, held, images[0], depth, what="sequence frame 0")

    bench.run([producer, consumer], test_name)


def test_delta_frames(test_name):
    """Delta frames: a frame of only the rows that changed shows its base's words in every other
    row, at its base's bit depth; the base is kept while a delta uses it and freed after; a delta
    of a base not held (gone, never sent, or itself a delta) is refused row by row, and one that
    claims more rows than the frame as outside. After each step the counters equal the reference
    model's (sim.models.slots_model), and every frame shown reads back as numpy composes it."""
    from sim.models.slots_model import SlotPolicy

    dmd = SHORT_DMD
    rows = dmd.rows
    bench = Bench(dmd, slots=4)
    dut = bench.dut
    policy = SlotPolicy(rows, 4)
    rng = np.random.default_rng(5)
    key = store_stim.random_image(dmd, 11)
    changed = [store_stim.random_image(dmd, 12 + k) for k in range(3)]
    carried = [[2, 3, 4, 17], [0, 9, 23], [5]]
    key2 = store_stim.random_image(dmd, 20)

    def composed(k):
        image = key.copy()
        image[carried[k]] = changed[k][carried[k]]
        return image

    async def send(ctx, image, frame, record, depth=3, base=0, n=0):
        for row in record:
            policy.row(frame, row, depth, base=base, carried=n)
        await bench.feed(ctx, image, frame, rows=record, base=base, carried=n)
        await bench.settle(ctx)
        assert bench.counters(ctx) == policy.counters, f"after frame {frame}"

    async def show(ctx, frame, image):
        want = policy.ask()
        assert want == frame
        slot, got, depth = await bench.ask(ctx)
        assert (got, depth) == (frame, policy.depth(frame)) == (frame, 3)
        for plane in store_stim.stored_planes(depth):
            words = await bench.read(ctx, slot, plane)
            store_stim.check_plane(dmd, image, plane, words, what=f"frame {frame}")
        # the occupancy: at least the composed frame's (a block wrongly empty would be cleared)
        keep = sum(1 << p for p in store_stim.stored_planes(depth))
        got_occ = np.array(await bench.occupancy(ctx, slot), dtype=np.uint8)
        need = bitplane.occupancy(image, dmd.rows_per_block) & keep
        assert np.array_equal(got_occ & need, need), (frame, got_occ, need)
        return slot

    async def release(ctx, slot, frame):
        policy.release(frame)
        await bench.release(ctx, slot)
        for _ in range(20):
            await ctx.tick("dmd")

    async def testbench(ctx):
        ctx.set(dut.bit_depth, 3)
        await send(ctx, key, 1, range(rows))
        held = await show(ctx, 1, key)
        ctx.set(dut.bit_depth, 8)              # a delta keeps its base's depth
        for k, frame in enumerate((2, 3)):
            order = list(rng.permutation(carried[k]))
            await send(ctx, changed[k], frame, order, depth=8, base=1, n=len(carried[k]))
            slot = await show(ctx, frame, composed(k))
            await release(ctx, held, 1 if k == 0 else 2)     # the key: kept, a delta uses it
            held = slot
        assert sorted(policy.in_state("KEPT")) == [1]
        # refused: a delta of a delta, of a frame never sent, and one claiming too many rows
        await send(ctx, changed[2], 4, carried[2], base=3, n=1)
        await send(ctx, changed[2], 5, carried[2], base=77, n=1)
        await send(ctx, changed[2], 6, carried[2], base=1, n=rows + 1)
        # a third delta of the key, while the second is shown
        await send(ctx, changed[2], 7, carried[2], depth=8, base=1, n=1)
        image = key.copy()
        image[carried[2]] = changed[2][carried[2]]
        slot = await show(ctx, 7, image)
        await release(ctx, held, 3)
        held = slot
        # a new whole frame; once no delta of the first key is held, that key is freed
        ctx.set(dut.bit_depth, 3)
        await send(ctx, key2, 8, range(rows))
        slot = await show(ctx, 8, key2)
        await release(ctx, held, 7)
        assert policy.in_state("KEPT") == []
        await send(ctx, changed[0], 9, carried[0], base=1, n=len(carried[0]))
        assert bench.counters(ctx) == policy.counters
        counted = policy.counters
        assert counted["rows_no_base"] == 2 * len(carried[2]) + len(carried[0]), counted
        assert counted["rows_outside"] == len(carried[2]) and counted["frames_complete"] == 5, counted

    bench.run([testbench], test_name, deadline=3e-3)


def test_calibration_loss_forgets_every_frame(test_name):
    """The memory loses its calibration while a held frame is being read, with another frame
    complete and a third arriving: the read ends (its words as stored, or zeros once lost), every
    frame is forgotten and counted, nothing is read of the lost memory (the model checks every
    word read), and the first frame stored after the memory is back is given and read exactly."""
    bench = Bench(SHORT_DMD)
    dut = bench.dut
    images = {f: store_stim.random_image(SHORT_DMD, 900 + f) for f in range(1, 5)}
    phase = {}

    async def producer(ctx):
        ctx.set(dut.bit_depth, 1)
        await bench.feed(ctx, images[1], 1)
        await wait_until(ctx, lambda: "held" in phase)
        await bench.feed(ctx, images[2], 2)
        await bench.feed(ctx, images[3], 3, rows=range(4))
        await bench.settle(ctx)
        phase["fed"] = True
        await wait_until(ctx, lambda: "recovered" in phase)
        await bench.feed(ctx, images[4], 4)

    async def consumer(ctx):
        slot, frame, _ = await bench.ask(ctx)
        assert frame == 1
        phase["held"] = True
        await wait_until(ctx, lambda: "fed" in phase, domain="dmd")
        # lost a little after the read starts, regained 2 us later
        bench.model.lose_calibration(bench.model.now + 60e-9, 2e-6)
        plane = store_stim.stored_planes(1)[0]
        words = await bench.read(ctx, slot, plane)
        want = [int(w) for w in bitplane.plane_words(images[1])[plane].reshape(-1)]
        assert all(w in (0, v) for w, v in zip(words, want, strict=True)), "only stored words or zeros"
        assert words[-1] == 0 != want[-1], "the loss cut the read short"
        assert ctx.get(dut.lost)
        await bench.recovered(ctx, frames_lost=3)
        phase["recovered"] = True
        # the frame stored after the loss is the one given (not frame 2, lost); the lost one
        # held is handed back without complaint
        await bench.receive(ctx, images[4], 4)
        await bench.release(ctx, slot)
        for _ in range(20):
            await ctx.tick("dmd")
        assert bench.counters(ctx)["bad_releases"] == 0

    bench.run([producer, consumer], test_name, deadline=1e-3)


@pytest.mark.parametrize("moment", ["words", "command"])
def test_calibration_loss_mid_burst(moment, test_name):
    """The memory loses its calibration while the writer is in the middle of a frame's first
    burst: half its words in the write FIFO and the rest still coming ("words"), or all of them
    there and the command due in the very cycle of the loss ("command"). The loss is timed on
    the port's own signals, and the test checks where it landed. From the loss cycle until the
    memory is back the port is given nothing (the model refuses any traffic while not
    calibrated, and so does the test) and nothing is written to the memory; the interrupted
    frame is forgotten and never given (its rows that come after the recovery make an incomplete
    frame, abandoned for the next one), and the next frame is stored and read back exactly."""
    bench = Bench(SHORT_DMD)
    dut, port = bench.dut, bench.dut.mcb_write
    interrupted, image = (store_stim.random_image(SHORT_DMD, 950 + i) for i in range(2))
    seen = {}

    async def producer(ctx):
        ctx.set(dut.bit_depth, 1)
        await bench.feed(ctx, interrupted, 1)
        await bench.feed(ctx, image, 2)

    async def watcher(ctx):
        # counts the port's edges as its model does (edge n at n / SYNC_HZ), and the words given
        # since the last command
        cycle = pushed = 0
        due = None
        async for _clk, _rst, wr_en, cmd_en, bl, calib_done in ctx.tick().sample(
                port.wr_en, port.cmd_en, port.cmd_bl, port.calib_done):
            cycle += 1
            pushed = (0 if cmd_en else pushed) + wr_en
            if due is None and wr_en:
                # the burst's first word: its words come one per edge, then its command; the
                # loss lands on the edge chosen, taking that edge's inputs with the rest
                burst = bl + 1
                due = cycle + (burst // 2 if moment == "words" else burst - 1)
                bench.model.lose_calibration((due - 0.5) / SYNC_HZ, 2e-6)
            elif cycle == due:
                assert calib_done and not cmd_en
                seen.update(pushed=pushed, burst=bl + 1, written=len(bench.model.write_log))
            elif due is not None and cycle > due:
                # from the loss cycle (sampled at due + 1) until the memory is back: nothing
                assert calib_done or not (wr_en or cmd_en), f"port traffic while lost, edge {cycle}"
                if cycle == due + 1:
                    assert not calib_done, "the loss landed on the edge chosen"
                elif calib_done:
                    seen["back"] = len(bench.model.write_log)
                    return

    async def consumer(ctx):
        # asked before the loss: the first frame given is the one sent after it
        await bench.receive(ctx, image, 2)
        await bench.recovered(ctx, frames_lost=1)
        counters = bench.counters(ctx)
        assert counters["frames_complete"] == 1 and counters["frames_abandoned"] == 1, counters

    bench.run([producer, watcher, consumer], test_name)
    assert seen["burst"] == 2 * 16, "the first burst: 16 rows of 2 words"
    if moment == "words":
        assert 0 < seen["pushed"] < seen["burst"], seen
    else:
        assert seen["pushed"] == seen["burst"], seen
    assert seen["written"] == seen["back"] == 0, "nothing of the interrupted frame reached the memory"


def test_sequence_entries(test_name):
    """A sequence of 3 frames (6 bits) played by an entry table, once: the entries' slots in the
    table's order (the same slot twice in a row too), each answer with its entry's settings and
    bit depth (the frame's own for 0 or more than it has), an entry whose slot is outside the
    sequence skipped and counted, the last entry's answer marked last and no answer after it,
    until ``sequence_start`` plays the entries from the first again; played in a loop, the
    entries wrap round."""
    bench = Bench(SHORT_DMD)
    dut = bench.dut
    images = {f: store_stim.random_image(SHORT_DMD, 1300 + f) for f in range(3)}
    # (slot, lsb, dark, follow, camera_off, depth)
    table = [(2, 100, 0, 0, 0, 0), (0, 0, 40, 1, 1, 3), (0, 0, 0, 1, 0, 8), (5, 0, 0, 0, 0, 1), (1, 60, 0, 1, 0, 6)]
    got = []

    async def producer(ctx):
        await bench.write_entries(ctx, [{"slot": slot, "lsb": lsb, "dark": dark, "follow": follow,
                                         "camera_off": camera_off, "depth": depth}
                                        for slot, lsb, dark, follow, camera_off, depth in table])
        await bench.feed_sequence(ctx, images, (0, 1, 2), depth=6)

    async def answer(ctx, wait=None):
        """The next answer's (slot, frame id, showing and bit depth), or None if none comes in
        ``wait`` cycles."""
        payload = await bench.answer(ctx, wait)
        if payload is None:
            return None
        s = payload.showing
        return (int(payload.slot), int(payload.frame_id),
                tuple(int(x) for x in (s.lsb, s.dark, s.follow, s.camera_off, s.last, payload.bit_depth)))

    async def consumer(ctx):
        held = None
        for _ in range(4):
            slot, frame, showing = await answer(ctx)
            assert slot == frame
            got.append((slot, showing))
            if held is not None and held != slot:
                await bench.release(ctx, held)
            held = slot
        assert await answer(ctx, wait=400) is None, "an answer after the last entry of a sequence played once"
        assert bench.counters(ctx)["entries_skipped"] == 1
        ctx.set(dut.sequence_start, 1)
        await ctx.tick()
        ctx.set(dut.sequence_start, 0)
        got.append(((await answer(ctx))[0], None))
        ctx.set(dut.loop, 1)
        for _ in range(4):
            slot, _, showing = await answer(ctx)
            got.append((slot, showing[4]))
        assert bench.counters(ctx)["bad_releases"] == 0

    bench.run([producer, consumer], test_name, deadline=8e-4)
    assert got[:4] == [(2, (100, 0, 0, 0, 0, 6)), (0, (0, 40, 1, 1, 0, 3)), (0, (0, 0, 1, 0, 0, 6)),
                       (1, (60, 0, 1, 0, 1, 6))]
    # started again: entry 0; in a loop: entries 1, 2, (3 skipped) 4, 0, none marked last
    assert got[4:] == [(2, None), (0, 0), (0, 0), (1, 0), (2, 0)]


def test_sequence_entries_pick_planes(test_name):
    """Entries that leave out their frame's most significant planes (``skip``), of an 8-bit and a
    4-bit frame: each answer gives the entry's depth and its lowest stored plane, and the planes
    read from there up are the image bits the entry names (numpy's); an entry whose planes are
    not all in its frame (skip + depth beyond the frame's, or no plane left below the skip) is
    skipped and counted, as one whose slot is outside the sequence."""
    bench = Bench(SHORT_DMD)
    dut = bench.dut
    images = [store_stim.random_image(SHORT_DMD, 1400 + f) for f in range(2)]
    depths = (8, 4)                  # slot 0 keeps bits 0..7 of its image, slot 1 bits 4..7
    # (slot, depth, skip, (lowest image bit, bits) shown or None: skipped)
    table = [(0, 0, 0, (0, 8)), (0, 1, 7, (0, 1)), (0, 2, 3, (3, 2)), (0, 1, 3, (4, 1)), (0, 2, 7, None),
             (1, 1, 3, (4, 1)), (1, 2, 3, None), (1, 0, 4, None), (1, 0, 2, (4, 2)), (1, 8, 0, (4, 4)),
             (1, 3, 0, (5, 3)), (0, 2, 6, (0, 2))]

    async def producer(ctx):
        await bench.write_entries(ctx, [{"slot": slot, "depth": depth, "skip": skip} for slot, depth, skip, _ in table])
        ctx.set(dut.sequence_length, len(images))
        for f, depth in enumerate(depths):
            ctx.set(dut.bit_depth, depth)
            for _ in range(3):
                await ctx.tick()
            await bench.feed(ctx, images[f], f)

    async def consumer(ctx):
        held = None
        for index, (slot, _, _, shown) in enumerate(table):
            if shown is None:
                continue
            payload = await bench.answer(ctx)
            lowest_bit, bits = shown
            assert (int(payload.slot), int(payload.bit_depth)) == (slot, bits), f"entry {index}"
            low = int(payload.low_plane)
            for k in range(bits):
                words = await bench.read(ctx, slot, low + k)
                store_stim.check_plane(SHORT_DMD, images[slot] >> lowest_bit, k, words,
                                       what=f"entry {index}'s plane {k}")
            if held is not None and held != slot:
                await bench.release(ctx, held)
            held = slot
        assert await bench.answer(ctx, wait=400) is None, "an answer after the last entry of a sequence played once"
        assert bench.counters(ctx)["entries_skipped"] == sum(shown is None for *_, shown in table)
        assert bench.counters(ctx)["bad_releases"] == 0

    bench.run([producer, consumer], test_name, deadline=8e-4)


#: A store whose sequence spans slots beyond its live ones (as the projector's 170 XGA slots
#: beyond its 16 live ones), small enough to simulate: 12 slots, 4 live.
SEQUENCE_SLOTS, LIVE = 12, 4


def test_sequence_beyond_the_live_slots(test_name):
    """A sequence of 12 frames on a store of 12 slots of which 4 are live (kept in registers):
    frames of every bit depth sent in a random order load every slot; the sequence plays in
    order, each frame read back exactly (every stored plane and the occupancy map, numpy's) from
    its slot, then by an entry table that names slots on both sides of the live ones in any
    order. A delta frame for a slot beyond the live ones is refused (no base), as are rows of a
    frame complete (duplicate) and beyond the sequence (stale), each counted."""
    bench = Bench(SHORT_DMD, slots=SEQUENCE_SLOTS, live=LIVE)
    dut = bench.dut
    n = SEQUENCE_SLOTS
    rng = random.Random(12)
    images = {f: store_stim.random_image(SHORT_DMD, 1500 + f) for f in range(n)}
    depths = {f: 1 + (f * 3) % 8 for f in range(n)}
    entries = [11, 4, 0, 9, 9, 5, 3, 7]

    async def producer(ctx):
        ctx.set(dut.sequence_length, n)
        for _ in range(3):
            await ctx.tick()
        # a delta frame of slot 7 (beyond the live ones), before its whole frame: refused
        await bench.feed(ctx, images[7], 7, rows=range(3), base=0, carried=3)
        order = list(range(n))
        rng.shuffle(order)
        for f in order:
            ctx.set(dut.bit_depth, depths[f])
            await ctx.tick()
            await bench.feed(ctx, images[f], f)
        await bench.feed(ctx, images[9], 9, rows=range(5))       # complete already: duplicate
        await bench.feed(ctx, images[1], n, rows=range(2))       # beyond the sequence: stale

    async def consumer(ctx):
        held = None
        for f in range(n):
            slot, frame, depth = await bench.ask(ctx)
            assert (slot, frame, depth) == (f, f, depths[f]), f"sequence frame {f}"
            await bench.check_frame(ctx, slot, images[f], depth, what=f"sequence frame {f}")
            if held is not None:
                await bench.release(ctx, held)
            held = slot
        counters = bench.counters(ctx)
        assert counters["frames_complete"] == n
        assert (counters["rows_no_base"], counters["rows_duplicate"], counters["rows_stale"]) == (3, 5, 2), counters
        # the same frames by entries, played once
        await bench.write_entries(ctx, [{"slot": slot} for slot in entries])
        ctx.set(dut.sequence_start, 1)
        await ctx.tick("dmd")
        ctx.set(dut.sequence_start, 0)
        for index, slot in enumerate(entries):
            payload = await bench.answer(ctx)
            assert (int(payload.slot), int(payload.frame_id), int(payload.bit_depth)) == (slot, slot, depths[slot]), \
                f"entry {index}"
            assert int(payload.showing.last) == (index == len(entries) - 1)
            if slot >= LIVE:
                await bench.check_frame(ctx, slot, images[slot], depths[slot], what=f"entry {index}")
            if held != slot:
                await bench.release(ctx, held)
            held = slot
        assert await bench.answer(ctx, wait=400) is None, "an answer after the last entry of a sequence played once"
        assert bench.counters(ctx)["bad_releases"] == 0

    bench.run([producer, consumer], test_name, deadline=3e-3)


def test_entry_table_beyond_a_dlpc350s_buffer(test_name):
    """300 entries (more than the 256 an 8-bit index names, and than a DLPC350's 48 planes), each
    a slot of a 12-frame sequence on both sides of the live ones, some skipped: played once, the
    answers are the entries' slots in the table's order, each its entry's depth, the last marked."""
    bench = Bench(SHORT_DMD, slots=SEQUENCE_SLOTS, live=LIVE)
    n = SEQUENCE_SLOTS
    images = {f: store_stim.random_image(SHORT_DMD, 1700 + f) for f in range(n)}
    # (slot, depth, skip): every 7th entry leaves out all 6 planes of its 6-bit frame: skipped
    table = [((k * 7) % n, 1 + k % 6, 6 if k % 7 == 3 else 0) for k in range(300)]
    shown = [(slot, depth) for slot, depth, skip in table if skip == 0]

    async def producer(ctx):
        await bench.write_entries(ctx, [{"slot": slot, "depth": depth, "skip": skip} for slot, depth, skip in table])
        await bench.feed_sequence(ctx, images, range(n), depth=6)

    async def consumer(ctx):
        held = None
        for index, (slot, depth) in enumerate(shown):
            payload = await bench.answer(ctx)
            assert (int(payload.slot), int(payload.bit_depth)) == (slot, depth), f"entry {index}"
            assert int(payload.showing.last) == (index == len(shown) - 1)
            if held is not None and held != slot:
                await bench.release(ctx, held)
            held = slot
        assert await bench.answer(ctx, wait=400) is None, "an answer after the last entry of a sequence played once"
        assert bench.counters(ctx)["entries_skipped"] == len(table) - len(shown)

    bench.run([producer, consumer], test_name, deadline=3e-3)


def test_sequence_slots_walked_on_mode_change_and_loss(test_name):
    """The slots beyond the live ones are walked, one a cycle, when the mode changes or the memory
    is lost. A sequence of 12 frames plays up to frame 10 (a slot beyond the live ones), held;
    the sequence is cut to 11 frames: every other slot is freed (its frame sent again is taken),
    the held one is kept (its rows refused as shown) until released, then taken again. The
    sequence plays again, frame 10 exact. Then the memory loses its calibration while frame 10
    is held: all 11 frames are counted lost, the held one is handed back without complaint, and
    the frames sent again after the recovery play in order, exact."""
    bench = Bench(SHORT_DMD, slots=SEQUENCE_SLOTS, live=LIVE)
    dut = bench.dut
    n = SEQUENCE_SLOTS
    images = {f: store_stim.random_image(SHORT_DMD, 1600 + f) for f in range(n)}
    phase = {}

    async def send(ctx, frames):
        for f in frames:
            await bench.feed(ctx, images[f], f)
        await bench.settle(ctx)

    async def producer(ctx):
        ctx.set(dut.bit_depth, 1)
        ctx.set(dut.sequence_length, n)
        for _ in range(3):
            await ctx.tick()
        await send(ctx, range(n))
        await wait_until(ctx, lambda: "held" in phase)
        ctx.set(dut.sequence_length, n - 1)
        await send(ctx, [10])                                     # held: refused as shown
        await send(ctx, range(10))                                # freed by the walk: taken
        phase["resent"] = True
        await wait_until(ctx, lambda: "released" in phase)
        await send(ctx, [10])
        await wait_until(ctx, lambda: "recovered" in phase)
        await send(ctx, range(n - 1))

    async def play_to(ctx, last, check=()):
        """Ask for frames 0..last in order (each released when the next is given): the slot
        of ``last``, held."""
        held = None
        for f in range(last + 1):
            slot, frame, _ = await bench.ask(ctx)
            assert (slot, frame) == (f, f)
            if f in check:
                await bench.check_frame(ctx, slot, images[f], 1, what=f"sequence frame {f}")
            if held is not None:
                await bench.release(ctx, held)
            held = slot
        return held

    async def consumer(ctx):
        held = await play_to(ctx, 10)
        phase["held"] = True
        await wait_until(ctx, lambda: "resent" in phase, domain="dmd")
        counters = bench.counters(ctx)
        assert counters["rows_shown"] == SHORT_DMD.rows, counters
        assert counters["frames_complete"] == n + 10, counters
        await bench.release(ctx, held)
        phase["released"] = True
        for _ in range(2 * SHORT_DMD.rows):
            await ctx.tick("dmd")
        held = await play_to(ctx, 10, check=(0, 10))
        assert bench.counters(ctx)["frames_complete"] == n + 11
        bench.model.lose_calibration(bench.model.now + 60e-9, 2e-6)
        await ctx.tick("dmd").until(dut.lost)
        await bench.recovered(ctx, frames_lost=n - 1)
        await bench.release(ctx, held)
        phase["recovered"] = True
        await play_to(ctx, 10, check=(5, 9))
        assert bench.counters(ctx)["bad_releases"] == 0

    bench.run([producer, consumer], test_name, deadline=4e-3)


@pytest.mark.parametrize("dmd,width", [("dlp7000", 128), ("dlp7000", 64), ("dlp9500", 128), ("dlp650lnir", 128),
                                       ("dlp650lnir", 64), ("test", 64)])
def test_reader_commands_cover_each_run(dmd, width, seed):
    """The plane reader alone on each geometry and port width, its memory a testbench that
    answers each command's words in order: a request's runs of rows (a delta's rows from two
    slots, at random) are read as contiguous bursts of 64 port words and a shorter last one, at
    each run's address (the address map's), and every word comes out in order."""
    from amaranth.sim import Simulator

    from gateware.store.addresses import AddressMap
    from gateware.store.reader import Reader
    from spec.facts import DMDS

    geometry, rng = DMDS[dmd], random.Random(seed)
    dut = Reader(geometry, slots=16, width=width, domain="sync")
    amap, word_bytes = AddressMap(geometry, 16), width // 8
    row_words = geometry.words_per_row * 64 // width
    requests = []
    for delta in (False, True, False):
        count = rng.randrange(1, 40)
        first = rng.randrange(geometry.rows - count + 1)
        base = rng.randrange(16)
        sources = {row: rng.choice((5, base)) if delta else 5 for row in range(first, first + count)}
        requests.append(({"slot": 5, "plane": rng.randrange(8), "first_row": first, "row_count": count},
                         delta, sources))

    def bursts(request, sources):
        """The commands (byte address, port words) a request's runs make."""
        out, rows = [], list(range(request["first_row"], request["first_row"] + request["row_count"]))
        while rows:
            run = [rows.pop(0)]
            while rows and sources[rows[0]] == sources[run[0]]:
                run.append(rows.pop(0))
            at = amap.address(sources[run[0]], request["plane"], run[0])
            words = len(run) * row_words
            while words:
                burst = min(words, 64)
                out.append((at, burst))
                at, words = at + burst * word_bytes, words - burst
        return out

    commands, got = [], []

    async def bench(ctx):
        port, src = dut.mcb, dut.sources
        ctx.set(port.calib_done, 1)
        ctx.set(dut.planes.ready, 1)
        pending, sent, delta, lookup = [], 0, False, {}
        for request, delta_now, sources in requests:
            want = request["row_count"] * row_words
            ctx.set(dut.requests.payload, request)
            ctx.set(dut.requests.valid, 1)
            asked, done = False, len(got) + want
            lookup = sources
            while len(got) < done:
                # the memory: a word a cycle of the commands taken; the row map: a read port
                ctx.set(port.rd_empty, not pending)
                ctx.set(port.rd_data, pending[0] if pending else 0)
                _, _, ready, cmd_en, addr, bl, rd_en, en, row, valid, word = await ctx.tick().sample(
                    dut.requests.ready, port.cmd_en, port.cmd_byte_addr, port.cmd_bl, port.rd_en, src.en,
                    src.row, dut.planes.valid, dut.planes.payload)
                if ready and not asked:
                    asked = True
                    ctx.set(dut.requests.valid, 0)
                if cmd_en:
                    commands.append((addr, bl + 1))
                    pending += range(sent, sent + bl + 1)
                    sent += bl + 1
                if rd_en and pending:
                    pending.pop(0)
                if valid:
                    got.append(word)
                if en:
                    delta = delta_now
                    ctx.set(src.source, lookup.get(row, 0))
                    ctx.set(src.delta, delta)

    sim = Simulator(dut)
    sim.add_clock(5e-9)
    sim.add_testbench(bench)
    sim.run()
    assert commands == [b for request, _, sources in requests for b in bursts(request, sources)]
    assert got == list(range(len(got))) and len(got) == sum(r["row_count"] for r, _, _ in requests) * row_words


@pytest.mark.parametrize("width", [64, 128])
def test_reader_reads_the_high_slots(width, test_name):
    """The plane reader with as many slots as slot numbers name (up to 40; every slot of the memory
    is the product's case, once ``SLOT_BITS`` names them) on the MCB model: every plane of the
    last slot and of a middle one is read at the address map's address, whole frames and a
    delta's rows shown from both slots, and each word comes out as the memory holds it; a
    request for a slot past the last is dropped and counted."""
    from gateware.store.addresses import AddressMap
    from gateware.store.layouts import SLOT_BITS
    from gateware.store.reader import Reader

    slots = min(40, 2**SLOT_BITS)
    last, middle, delta = slots - 1, slots // 2 + 1, 1
    dmd = TEST_DMD
    dut = Reader(dmd, slots=slots, width=width, domain="sync")
    amap = AddressMap(dmd, slots)
    model = McbModel(amap.end, ports=1, widths=widths(dut.mcb))
    model.memory[:] = np.random.default_rng(5).integers(0, 2**63, model.memory.size, dtype=np.uint64)
    requests = [(slot, plane, 0, dmd.rows) for slot in (last, middle) for plane in range(8)]
    requests += [(delta, 6, 3, 30), (delta, 2, 0, dmd.rows)]
    bad = [(slots, 0, 0, dmd.rows)] if slots < 2**SLOT_BITS else []
    got = []

    def source(slot, row):
        """The slot whose words a row of ``slot`` shows: the delta's rows show the last slot's and
        the middle one's in stretches of 5 rows (none its own)."""
        return (last, middle, middle, last)[row // 5 % 4] if slot == delta else slot

    async def row_map(ctx):
        # the row map's read port: a delta in slot ``delta``, whole frames elsewhere
        src = dut.sources
        async for _clk, _rst, en, slot, row in ctx.tick().sample(src.en, src.slot, src.row):
            if en:
                ctx.set(src.source, source(int(slot), int(row)))
                ctx.set(src.delta, slot == delta)

    async def sequencer(ctx):
        while not ctx.get(dut.mcb.calib_done):
            await ctx.tick()
        for slot, plane, first, rows in bad + requests:
            ctx.set(dut.requests.payload, {"slot": slot, "plane": plane, "first_row": first, "row_count": rows})
            ctx.set(dut.requests.valid, 1)
            await ctx.tick().until(dut.requests.ready)
            ctx.set(dut.requests.valid, 0)
            if slot < slots:
                got.append(await stream_collect(ctx, dut.planes, rows * dmd.words_per_row * 64 // width, convert=int))
        for _ in range(10):
            await ctx.tick()
        assert ctx.get(dut.bad_requests) == len(bad)

    simulate(dut, [sequencer], name=test_name, clocks={"sync": 200e6},
             processes=[row_map, amaranth_process(model.ports[0], dut.mcb, domain="sync", frequency=200e6)],
             deadline=2e-3)

    # the words: each row's from its source slot's plane, as the memory holds them
    for (slot, plane, first, rows), transfers in zip(requests, got, strict=True):
        want = [int(model.memory[amap.address(source(slot, row), plane, row, word) // 8])
                for row in range(first, first + rows) for word in range(dmd.words_per_row)]
        assert store_stim.plane_words(transfers, width) == want, f"slot {slot} plane {plane}"
    # the commands: each run of rows from one slot in bursts of 64 port words from its address
    word_bytes, commands = width // 8, []
    for slot, plane, first, rows in requests:
        row = first
        while row < first + rows:
            end = row + 1
            while end < first + rows and source(slot, end) == source(slot, row):
                end += 1
            at, stop = amap.address(source(slot, row), plane, row), amap.address(source(slot, row), plane, end)
            while at < stop:
                words = min(64, (stop - at) // word_bytes)
                commands.append((at, words))
                at += words * word_bytes
            row = end
    assert [(at, words) for _instr, words, at in model.ports[0].command_log] == commands


def _broker_slots():
    """Enough slots for numbers above 15 once slot numbers are wide enough (``SLOT_BITS``); with
    4-bit slot numbers, every one of the 16."""
    from gateware.store.layouts import SLOT_BITS
    return min(40, 2**SLOT_BITS)


@pytest.mark.parametrize("slots", [3, _broker_slots()])
def test_broker_occupancy_against_a_model_store(slots, seed, test_name):
    """The frame broker between a model store (frames on random slots, random planes in every
    block, its occupancy port answering one cycle after the lookup) and a sequencer that looks a
    slot up every cycle: a slot's map reads as the store answered it for the slot's latest frame,
    from the first cycle that frame is on offer. After ``store_lost`` (while a frame is on offer,
    mid-scan, as the scan's last planes come back, and at random) every slot reads empty until a
    frame on it is offered again, and that frame reads its planes."""
    from gateware.store.broker import FrameBroker
    from spec.facts import DMDS

    dmd = DMDS["dlp7000"]
    blocks, empty = dmd.blocks, [0] * dmd.blocks
    rng = random.Random(seed)
    dut = FrameBroker(dmd, slots=slots)
    # every slot, the highest first, then at random; planes never zero, so that a map forgotten
    # or not yet written never passes for the frame's
    order = [slots - 1, *range(slots), *(rng.randrange(slots) for _ in range(40))]
    frames = [(slot, 1000 + i, [rng.randrange(1, 256) for _ in range(blocks)]) for i, slot in enumerate(order)]
    store_maps = {}                   # the store's occupancy: slot -> each block's planes
    planes_of = {}                    # frame id -> each block's planes, as the store answered
    losses = {"on offer": None, "mid-scan": None, "scan's end": None, "random": None}
    random_loss = rng.randrange(100, 800)
    seen = {"empty after loss": 0, "planes after loss": 0}
    taken = []

    async def occupancy_port(ctx):
        # the store's registered read: what was asked at the clock edge, answered the next cycle
        # (a block past the last answers junk, which the broker must not keep)
        async for _, _, slot, block in ctx.tick().sample(dut.store_occupancy.slot, dut.store_occupancy.block):
            maps = store_maps.get(slot)
            ctx.set(dut.store_occupancy.planes, maps[block] if maps and block < blocks else rng.randrange(256))

    async def store(ctx):
        for slot, frame_id, planes in frames:
            ctx.set(dut.ask.ready, 1)
            await ctx.tick().until(dut.ask.valid)
            ctx.set(dut.ask.ready, 0)
            for _ in range(rng.choice([0, 0, 1, 5])):
                await ctx.tick()
            # the slot's map is complete before the frame is given out
            store_maps[slot], planes_of[frame_id] = planes, planes
            ctx.set(dut.offered.payload, {"slot": slot, "frame_id": frame_id, "bit_depth": 8})
            ctx.set(dut.offered.valid, 1)
            await ctx.tick().until(dut.offered.ready)
            ctx.set(dut.offered.valid, 0)

    async def sequencer(ctx):
        rows = {}                     # what each slot's map reads for a lookup made this cycle
        on_offer = None               # the frame on offer, from the first cycle it is
        asked = None                  # last cycle's lookup: (slot, what it reads, after a loss)
        lost = loss_left = 0
        after_loss = last_asked = False
        cycle = 0
        while len(taken) < len(frames):
            if asked is not None:
                slot, want, since_loss = asked
                got = [int(ctx.get(dut.occupancy[b])) for b in range(blocks)]
                assert got == want, f"cycle {cycle}: slot {slot} reads {got}, not {want}"
                if since_loss:
                    seen["planes after loss" if want != empty else "empty after loss"] += 1
            if lost:
                # lookups from the cycle after a loss read every map empty, the frame on offer's too
                rows, after_loss = {}, True
            valid, payload = ctx.get(dut.frames.valid), ctx.get(dut.frames.payload)
            if valid and on_offer is None:
                on_offer = int(payload.frame_id)
                rows[int(payload.slot)] = planes_of[on_offer]

            # the loss: over when its cycles are, else one of the three begins
            lost, begins = loss_left > 0, None
            if lost:
                loss_left -= 1
            else:
                if losses["on offer"] is None and valid and len(taken) > slots // 2:
                    begins = "on offer"
                elif (losses["mid-scan"] is None and losses["on offer"] is not None
                      and ctx.get(dut.store_occupancy.block) == blocks // 2):
                    begins = "mid-scan"
                elif losses["scan's end"] is None and losses["mid-scan"] is not None and last_asked:
                    # the cycle the last block's planes come back
                    begins = "scan's end"
                elif losses["random"] is None and cycle >= random_loss:
                    begins = "random"
                if begins:
                    losses[begins], lost, loss_left = cycle, True, rng.randrange(3)
            ctx.set(dut.store_lost, lost)
            last_asked = ctx.get(dut.store_occupancy.block) == blocks - 1

            # the frame on offer is looked up at once, else a slot at random; a lookup the cycle a
            # loss begins may still read the map
            slot = int(payload.slot) if valid else rng.randrange(slots)
            ctx.set(dut.occ_slot, slot)
            asked = None if begins else (slot, rows.get(slot, empty), after_loss)
            ready = rng.random() < 0.5
            ctx.set(dut.frames.ready, ready)
            await ctx.tick()
            cycle += 1
            if valid and ready:
                assert int(payload.frame_id) == frames[len(taken)][1]
                taken.append(on_offer)
                on_offer = None

    simulate(dut, [store, sequencer], name=test_name, processes=[occupancy_port], deadline=100e-6)
    assert taken == [frame_id for _, frame_id, _ in frames]
    assert None not in losses.values(), losses
    assert seen["empty after loss"] > slots and seen["planes after loss"] > 10, seen
