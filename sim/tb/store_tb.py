"""cocotb testbench of the store's generated Verilog (serialiser, slots, writer, reader) with the
MCB model on both ports, against numpy. Run by ``tests/test_store_verilog.py``."""

import cocotb
from amaranth.lib import data
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, RisingEdge, Timer, with_timeout

from gateware.protocol.layouts import pixel_layout
from gateware.store.layouts import SLOT_BITS, FrameInfo, PlaneRequest
from gateware.store.slots import SlotCounters
from sim.harness.cocotb_run import params
from sim.harness.cocotb_stream import StreamSink, StreamSource
from sim.harness.layout import unpack
from sim.models import bitplane_model as bitplane
from sim.models import store_stim
from sim.models.mcb_model import CocotbPort, McbModel
from spec.facts import DMDS

SYNC_NS, DMD_NS = 8, 5
#: plain-number stream payloads, named for the layout helpers
SLOT = data.StructLayout({"slot": SLOT_BITS})


class Bench:
    def __init__(self, dut):
        p = params()
        self.dut, self.dmd, self.slots = dut, DMDS[p["dmd"]], p["slots"]
        self.model = McbModel(p["memory_bytes"], widths=CocotbPort.widths(dut, "mcb_write", "mcb_read"))
        self.pixels = StreamSource(dut, "pixels", pixel_layout(self.dmd, 8, 16), dut.clk)
        self.frames = StreamSink(dut, "frames", FrameInfo, dut.dmd_clk)
        self.requests = StreamSource(dut, "requests", PlaneRequest, dut.dmd_clk)
        self.width = len(dut.planes__payload)          # plane words a transfer, times 64
        self.planes = StreamSink(dut, "planes", data.StructLayout({"words": self.width}), dut.dmd_clk)
        self.release_port = StreamSource(dut, "release", SLOT, dut.dmd_clk)
        dut.ask__valid.value = 0

    async def start(self):
        dut = self.dut
        cocotb.start_soon(Clock(dut.clk, SYNC_NS, unit="ns").start())
        await Timer(500, "ps")      # no edge of one clock at the time of an edge of the other
        cocotb.start_soon(Clock(dut.dmd_clk, DMD_NS, unit="ns").start())
        dut.bit_depth.value = 8
        dut.sequence_length.value = 0
        dut.rst.value = dut.dmd_rst.value = 1
        await ClockCycles(dut.clk, 3)
        dut.rst.value = dut.dmd_rst.value = 0
        cocotb.start_soon(CocotbPort(dut, "mcb_write", dut.clk, self.model.ports[0], SYNC_NS).run())
        cocotb.start_soon(CocotbPort(dut, "mcb_read", dut.dmd_clk, self.model.ports[1], DMD_NS).run())

    async def ask(self):
        dut = self.dut
        dut.ask__valid.value = 1
        while True:
            await RisingEdge(dut.dmd_clk)
            if dut.ask__ready.value:
                break
        dut.ask__valid.value = 0
        answer, = await self.frames.receive(1)
        return answer

    async def release(self, slot):
        await self.release_port.send([{"slot": slot}])

    async def read(self, slot, plane, first_row=0, row_count=None):
        row_count = self.dmd.rows if row_count is None else row_count
        await self.requests.send([{"slot": slot, "plane": plane, "first_row": first_row,
                                   "row_count": row_count}])
        transfers = await self.planes.receive(row_count * self.dmd.words_per_row * 64 // self.width)
        return store_stim.plane_words([t["words"] for t in transfers], self.width)

    async def occupancy(self, slot):
        dut, got = self.dut, []
        for block in range(self.dmd.blocks):
            dut.occupancy__slot.value = slot
            dut.occupancy__block.value = block
            await ClockCycles(dut.dmd_clk, 3)
            got.append(int(dut.occupancy__planes.value))
        return got

    async def show(self, image, frame_id, depth, what):
        """Send a frame, ask for it, read every stored plane whole, the occupancy, and the rows of
        single blocks (as a sequencer loading chosen blocks reads them); release it."""
        dmd = self.dmd
        self.dut.bit_depth.value = depth
        await self.pixels.send(store_stim.frame_beats(image, frame_id))
        answer = await with_timeout(self.ask(), 1, "ms")
        assert (answer["frame_id"], answer["bit_depth"]) == (frame_id, depth), answer
        stored = store_stim.stored_planes(depth)
        for plane in stored:
            words = await self.read(answer["slot"], plane)
            store_stim.check_plane(dmd, image, plane, words, what=what)
        store_stim.check_occupancy(dmd, image, depth, await self.occupancy(answer["slot"]), what=what)
        rows = dmd.rows_per_block
        for plane, block in ((stored[-1], dmd.blocks - 1), (stored[0], 1)):
            words = await self.read(answer["slot"], plane, block * rows, rows)
            store_stim.check_plane(dmd, image, plane, words, block * rows, rows, what=f"{what} block {block}")
        await self.release(answer["slot"])

    def counters(self):
        return unpack(SlotCounters, self.dut.counters.value.to_unsigned())


@cocotb.test()
async def every_bit_depth_and_extreme_images(dut):
    """Random images at bit depths 1..8, then every extreme image, each read back whole and by
    blocks."""
    bench = Bench(dut)
    await bench.start()
    dmd = bench.dmd
    frame_id = 1
    for depth in params()["depths"]:
        await bench.show(store_stim.random_image(dmd, depth), frame_id, depth, f"depth {depth}")
        frame_id += 1
    if params()["extremes"]:
        for name, image in bitplane.extreme_images(dmd.rows, dmd.columns, seed=2).items():
            await bench.show(image, frame_id, 8, name)
            frame_id += 1
    counters = bench.counters()
    assert counters["frames_complete"] == frame_id - 1
    assert all(v == 0 for k, v in counters.items() if k != "frames_complete"), counters
    assert int(dut.bad_requests.value) == 0
    store_stim.check_writes_inside(bench.model, dmd, bench.slots, range(bench.slots))


@cocotb.test()
async def sequence_beyond_the_live_slots(dut):
    """A stored sequence on every slot of a store whose live slots are fewer (``params()["live"]``):
    frames of every bit depth sent in reverse order, then given out in order, each read back
    whole (every stored plane and the occupancy map) from its own slot, twice round."""
    bench = Bench(dut)
    await bench.start()
    dmd, n = bench.dmd, bench.slots
    images = {f: store_stim.random_image(dmd, 3000 + f) for f in range(n)}
    depths = {f: 1 + (f * 5) % 8 for f in range(n)}
    dut.sequence_length.value = n
    await ClockCycles(dut.clk, 3)
    for f in reversed(range(n)):
        dut.bit_depth.value = depths[f]
        await ClockCycles(dut.clk, 1)
        await bench.pixels.send(store_stim.frame_beats(images[f], f))
    held = None
    for turn in range(2 * n):
        f = turn % n
        answer = await with_timeout(bench.ask(), 2, "ms")
        assert (answer["slot"], answer["frame_id"], answer["bit_depth"]) == (f, f, depths[f]), answer
        if turn < n or f >= params()["live"]:
            for plane in store_stim.stored_planes(depths[f]):
                store_stim.check_plane(dmd, images[f], plane, await bench.read(f, plane), what=f"frame {f}")
            store_stim.check_occupancy(dmd, images[f], depths[f], await bench.occupancy(f), what=f"frame {f}")
        if held is not None:
            await bench.release(held)
        held = f
    counters = bench.counters()
    assert counters["frames_complete"] == n
    assert all(v == 0 for k, v in counters.items() if k != "frames_complete"), counters
    assert int(dut.bad_requests.value) == 0
    store_stim.check_writes_inside(bench.model, dmd, bench.slots, range(bench.slots))
