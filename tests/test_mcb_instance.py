"""The MCB instance for the Spartan-6 top: the vendor wrapper gets every user-port signal of
both ports and every DDR2 pin, with the widths the generator gives them; the plane reader's
128-bit port reaches the wrapper's 64-bit one through the widener, checked on the MCB model."""

import re

import numpy as np
import pytest
from amaranth import Module
from amaranth.back import verilog
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from gateware.platform.mcb_instance import MODULE, McbInstance
from gateware.platform.read_widener import ReadWidener
from gateware.store import mcb
from gateware.store.addresses import AddressMap
from gateware.store.reader import Reader
from gateware.store.store import Store
from sim.harness.amaranth_sim import simulate, stream_collect
from sim.models import store_stim
from sim.models.mcb_model import McbModel, amaranth_process, widths
from spec.facts import DMDS, TEST_DMD


def test_instance_ports():
    top = Module()
    top.submodules.store = store = Store(TEST_DMD)
    top.submodules.mcb = inst = McbInstance()
    wiring.connect(top, store.mcb_write, inst.port0)
    wiring.connect(top, store.mcb_read, inst.port1)         # 128 bits: through the widener
    text = verilog.convert(top, ports=[], name="top")
    body = text[text.index(f"{MODULE} mcb"):]
    body = body[:body.index(");")]
    connected = set(re.findall(r"\.(\w+)\(", body))
    for n in (0, 1):
        for name in mcb.PortSignature().members:
            if name != "calib_done":
                assert f"c3_p{n}_{name}" in connected, f"c3_p{n}_{name} not connected"
        for clock in ("cmd_clk", "wr_clk", "rd_clk"):
            assert f"c3_p{n}_{clock}" in connected
    for pin in ("mcb3_dram_dq", "mcb3_dram_a", "mcb3_dram_ba", "mcb3_dram_udqs", "mcb3_dram_dqs_n",
                "mcb3_rzq", "mcb3_zio", "c3_calib_done", "c3_sys_clk", "c3_sys_rst_i"):
        assert pin in connected
    assert re.search(r"inout \[15:0\] mcb3_dram_dq", text)
    assert re.search(r"inout \[12:0\] mcb3_dram_a", text)


def test_wrapper_ports_are_64_bits():
    """The generated controller has two 64-bit ports (its port configuration; the store's
    128-bit reader port reaches port 1 through the widener: ``test_instance_ports``)."""
    text = McbInstance.blackbox_verilog()
    for n in (0, 1):
        assert re.search(rf"input \[63:0\] c3_p{n}_wr_data", text)
        assert re.search(rf"input \[7:0\] c3_p{n}_wr_mask", text)
        assert re.search(rf"output \[63:0\] c3_p{n}_rd_data", text)


class WidenedReader(wiring.Component):
    """The plane reader on a 64-bit MCB port through the widener, or on a 128-bit port."""

    def __init__(self, dmd, widened):
        self._reader = Reader(dmd, slots=SLOTS, domain="sync")
        self._widener = ReadWidener() if widened else None
        super().__init__({
            "requests": In(self._reader.requests.signature.flip()),
            "planes": Out(self._reader.planes.signature),
            "mcb": Out(mcb.PortSignature(64 if widened else 128)),
        })

    def elaborate(self, platform):
        m = Module()
        m.submodules.reader = reader = self._reader
        wiring.connect(m, wiring.flipped(self.requests), reader.requests)
        wiring.connect(m, reader.planes, wiring.flipped(self.planes))
        port = reader.mcb
        if self._widener:
            m.submodules.widener = widener = self._widener
            wiring.connect(m, reader.mcb, widener.user)
            port = widener.mcb
        wiring.connect(m, port, wiring.flipped(self.mcb))
        return m


SLOTS = 4
#: (plane, first row, rows): port-word bursts of 64 (two 64-bit commands each), a row alone (one
#: command of 16 words) and five rows (80 words: 64 + 16)
RUNS = [(3, 0, 96), (5, 700, 1), (3, 40, 5)]


def read_runs(dmd, widened, test_name):
    dut = WidenedReader(dmd, widened)
    model = McbModel(AddressMap(dmd, SLOTS).end, ports=1, widths=widths(dut.mcb))
    model.memory[:] = np.random.default_rng(3).integers(0, 2**63, model.memory.size, dtype=np.uint64)
    got = []

    async def sequencer(ctx):
        while not ctx.get(dut.mcb.calib_done):
            await ctx.tick()
        for plane, first, rows in RUNS:
            ctx.set(dut.requests.payload, {"slot": 1, "plane": plane, "first_row": first, "row_count": rows})
            ctx.set(dut.requests.valid, 1)
            await ctx.tick().until(dut.requests.ready)
            ctx.set(dut.requests.valid, 0)
            want = rows * dmd.words_per_row // 2
            got.append(await stream_collect(ctx, dut.planes, want, convert=int))

    simulate(dut, [sequencer], name=test_name, clocks={"sync": 200e6},
             processes=[amaranth_process(model.ports[0], dut.mcb, domain="sync", frequency=200e6)], deadline=1e-3)
    return model, got


@pytest.mark.parametrize("widened", [True, False], ids=["widened", "direct"])
def test_reader_through_the_widener(widened, test_name):
    """The 128-bit plane reader on a 64-bit model port through the widener reads what the memory
    holds, the first word of each pair in the low bits, as on a 128-bit port; the 64-bit port
    sees commands of at most 64 words covering exactly the rows asked for."""
    dmd = DMDS["dlp7000"]
    amap = AddressMap(dmd, SLOTS)
    model, got = read_runs(dmd, widened, test_name)
    for (plane, first, rows), transfers in zip(RUNS, got, strict=True):
        start = amap.address(1, plane, first) // 8
        want = model.memory[start:start + rows * dmd.words_per_row]
        assert store_stim.plane_words(transfers, 128) == [int(w) for w in want]
    # the commands, in order, run through each run's bytes from its first
    commands = iter(model.ports[0].command_log)
    for plane, first, rows in RUNS:
        address, end = amap.address(1, plane, first), amap.address(1, plane, first + rows)
        while address < end:
            _instr, words, at = next(commands)
            assert at == address and words <= 64
            address += words * model.ports[0].word_bytes
        assert address == end
    assert next(commands, None) is None
    if widened:     # a 128-bit command of 64 words is two of 64 on the 64-bit port
        assert [words for _instr, words, _at in model.ports[0].command_log[:4]] == [64] * 4
