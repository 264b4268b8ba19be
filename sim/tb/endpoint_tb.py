"""cocotb testbench of the endpoint's generated Verilog (stack + protocol parser + status).

Frames are MAC byte beats fed with :class:`~sim.harness.cocotb_stream.StreamSource`; the
expectations come from the reference model; replies are parsed by scapy.

Run by ``tests/test_protocol_endpoint_verilog.py``.
"""

import random

import cocotb
import numpy as np
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, RisingEdge, with_timeout
from scapy.layers.inet import ICMP, IP, UDP
from scapy.layers.l2 import ARP, Ether

from gateware.mac.layouts import ByteBeat
from gateware.protocol.layouts import pixel_layout
from gateware.wire import layout
from host import codec
from sim.harness.cocotb_run import params
from sim.harness.cocotb_stream import StreamSink, StreamSource
from sim.harness.layout import pack, unpack
from sim.models import endpoint_traffic as traffic
from sim.models import frames
from sim.models.net_model import Model
from sim.tb.endpoint_sim import assemble_rows
from spec import records, schedule
from spec.facts import DMDS
from spec.registers import PlaneOrder

A = frames.Addresses()


async def reset(dut):
    cocotb.start_soon(Clock(dut.clk, 8, unit="ns").start())
    dut.rst.value = 1
    dut.status.value = 0
    dut.registers__ready.value = 1
    dut.entries__ready.value = 1
    await ClockCycles(dut.clk, 3)
    dut.rst.value = 0


class TxCollector:
    """Takes every frame the block sends, with random backpressure."""

    def __init__(self, dut, stall, seed):
        self.dut, self.stall, self.rng = dut, stall, random.Random(seed)
        self.frames, self._current = [], bytearray()
        cocotb.start_soon(self._run())

    async def _run(self):
        dut, driven = self.dut, None
        while True:
            ready = not (self.rng.random() < self.stall)
            if ready != driven:
                dut.tx__ready.value = driven = ready
            await RisingEdge(dut.clk)
            if ready and dut.tx__valid.value:
                beat = unpack(ByteBeat, dut.tx__payload.value.to_unsigned())
                self._current.append(beat["data"])
                if beat["last"]:
                    self.frames.append(bytes(self._current))
                    self._current = bytearray()


class RegisterCollector:
    """Every register set and sequence entry the block hands on (its consumers are always
    ready), and the trigger and sequence-start pulses it gives."""

    def __init__(self, dut):
        self.dut, self.sets, self.entries, self.triggers, self.starts = dut, [], [], 0, 0
        cocotb.start_soon(self._run())

    async def _run(self):
        entry = layout(records.ENTRY)
        while True:
            await RisingEdge(self.dut.clk)
            if self.dut.registers__valid.value:
                self.sets.append(self.dut.registers__payload.value.to_unsigned())
            if self.dut.entries__valid.value:
                self.entries.append(unpack(entry, self.dut.entries__payload.value.to_unsigned()))
            self.triggers += int(self.dut.trigger.value)
            self.starts += int(self.dut.sequence_start.value)


def control_traffic(dmd):
    """Control and sequencer records, good and bad (values the projector cannot obey)."""
    wire = records.register_wire(schedule.plan(dmd, 200e6, depth=6).params.registers(dmd))
    return [
        codec.control_record(50, bit_depth=6, armed=1, software_trigger=True),
        codec.control_record(51, armed=3),
        codec.sequencer_record(wire, 52),
        codec.sequencer_record({**wire, "lsb": wire["lsb"] | 1}, 53),
        codec.sequencer_record({**wire, "order": PlaneOrder.GROUPS.value, "group_offsets": 4}, 54),
        codec.sequencer_record({**wire, "row_period": 0}, 55),
        codec.sequencer_record({**wire, "order": PlaneOrder.LSB_FIRST.value}, 56),
        codec.sequencer_record(wire, 57)[:-2],
    ]


def counters(dut):
    net = unpack(layout(records.NET_COUNTERS), dut.net_counters.value.to_unsigned())
    app = unpack(layout(records.APP_COUNTERS), dut.app_counters.value.to_unsigned())
    return net, app


async def feed(source, dut, traffic, rng, gap):
    for raw, bad in traffic:
        await ClockCycles(dut.clk, rng.randint(*gap))
        await source.send(frames.byte_beats(raw, bad))


def check_replies(tx, model):
    """Each reply as the model expects; ARP/ICMP replies (from the stack) and status replies
    (from the protocol) each in order, the two sources interleaved in any order."""
    assert len(tx) == len(model.replies), (len(tx), [k for k, _ in model.replies])
    stack = [(Ether(raw), None) for raw in tx if ARP in Ether(raw) or ICMP in Ether(raw)]
    status = [(Ether(raw), None) for raw in tx if UDP in Ether(raw)]
    expected_stack = [r for r in model.replies if r[0] != "status"]
    expected_status = [r for r in model.replies if r[0] == "status"]
    assert len(stack) == len(expected_stack) and len(status) == len(expected_status)
    for (reply, _), (kind, expect) in zip(stack + status, expected_stack + expected_status, strict=True):
        assert reply.src == A.mac_str and reply.dst == A.host_mac
        if kind == "arp":
            assert reply[ARP].op == 2 and reply[ARP].psrc == A.ip_str and reply[ARP].pdst == A.host_ip
            continue
        ip_sum = reply[IP].chksum
        del reply[IP].chksum
        assert Ether(bytes(reply))[IP].chksum == ip_sum, "IPv4 header checksum"
        if kind == "icmp":
            assert reply[ICMP].type == 0 and bytes(reply[ICMP])[4:] == expect["message"][4:]
            icmp_sum = reply[ICMP].chksum
            del reply[ICMP].chksum
            assert Ether(bytes(reply))[ICMP].chksum == icmp_sum, "ICMP checksum"
        else:
            head, body, _ = codec.decode(bytes(reply[UDP].payload))
            assert head["sequence"] == expect["sequence"] and body["clock_hz"] == 125_000_000


@cocotb.test()
async def mixed_traffic(dut):
    """Images, ARP, ping, status and every class of bad frame, random gaps and backpressure:
    rows, counters and replies as the model says."""
    await reset(dut)
    p = params()
    dmd = DMDS[p["dmd"]]
    dut.status.value = pack(layout(records.SYSTEM_STATUS), {"clock_hz": 125_000_000})
    rng = random.Random(4)
    image = np.random.default_rng(2).integers(0, 256, (dmd.rows, dmd.columns), dtype=np.uint8)
    model = Model(dmd, A.mac, A.ip, A.port)
    # records of 300 pixels: rows split across records
    good = [frames.udp(A, r) for r in codec.image_records(image, 6, pixels=300)]
    bad = [builder(A, good[0][42:]) for builder, _ in frames.BAD_FRAMES.values()]
    traffic = [(raw, False) for raw in good]
    for raw in bad + [frames.arp_request(A), frames.icmp_echo(A, b"abc" * 9),
                      frames.udp(A, codec.status_query(1000))] + [frames.udp(A, r) for r in control_traffic(dmd)]:
        traffic.insert(rng.randrange(len(traffic) + 1), (raw, False))
    traffic.insert(rng.randrange(len(traffic)), (good[3], True))
    for raw, flag in traffic:
        model.frame(raw, flag)

    source = StreamSource(dut, "rx", ByteBeat, dut.clk, idle=0.05, seed=1)
    pixels = StreamSink(dut, "pixels", pixel_layout(dmd), dut.clk, stall=0.2, seed=2)
    tx = TxCollector(dut, stall=0.2, seed=3)
    registers = RegisterCollector(dut)
    feeder = cocotb.start_soon(feed(source, dut, traffic, rng, (0, 40)))
    got = await with_timeout(pixels.receive(len(model.rows) * dmd.columns), 20, "ms")
    await feeder
    await ClockCycles(dut.clk, 2000)
    rows = assemble_rows([(t["frame"], t["row"], t["column"], t["pixels"][0]) for t in got], dmd.columns)
    assert rows == model.rows
    net, app = counters(dut)
    assert net == {k: model.counters[k] for k, _ in records.NET_COUNTERS}
    assert app == {k: model.counters[k] for k, _ in records.APP_COUNTERS}
    check_replies(tx.frames, model)
    assert registers.sets == [records.registers_bits(wire) for wire in model.registers]
    assert len(registers.sets) == 2
    assert unpack(layout(records.CONFIG), dut.settings.value.to_unsigned()) == model.config


@cocotb.test()
async def line_rate(dut):
    """Largest records (jumbo frames) back to back at GMII timing (24 idle cycles between
    frames): none is lost, and the stack never holds off the MAC (its decision cycles fit in the
    gap)."""
    await reset(dut)
    dmd = DMDS[params()["dmd"]]
    image = np.random.default_rng(3).integers(0, 256, (dmd.rows, dmd.columns), dtype=np.uint8)
    before, _ = counters(dut)
    encoded = codec.image_records(image, 1, limit=records.MAX_RECORD)
    assert len(encoded[0]) > 8000
    source = StreamSource(dut, "rx", ByteBeat, dut.clk)
    pixels = StreamSink(dut, "pixels", pixel_layout(dmd), dut.clk)
    TxCollector(dut, stall=0.0, seed=5)
    feeder = cocotb.start_soon(feed(source, dut, [(frames.udp(A, r), False) for r in encoded],
                                    random.Random(0), (24, 24)))
    got = await with_timeout(pixels.receive(dmd.rows * dmd.columns), 20, "ms")
    await feeder
    await ClockCycles(dut.clk, 20)
    net, _ = counters(dut)
    assert net["accepted"] - before["accepted"] == len(encoded)
    assert net["drop_overflow"] == 0
    assert source.stalls == 0, f"the stack held off the MAC for {source.stalls} cycles"
    rows = assemble_rows([(t["frame"], t["row"], t["column"], t["pixels"][0]) for t in got], dmd.columns)
    assert [r for _f, r, _d in rows] == list(range(dmd.rows))
    assert all(np.frombuffer(data, np.uint8).tolist() == image[r].tolist() for _f, r, data in rows)


@cocotb.test()
async def randomized_mix_ledger(dut):
    """Hundreds of frames (:func:`sim.models.endpoint_traffic.randomized_mix`), good and bad
    interleaved, random gaps, backpressure on both outputs: every counter equals the model's,
    every accepted row arrives, nothing else does."""
    await reset(dut)
    dmd = DMDS[params()["dmd"]]
    assert dmd == traffic.DMD, "the mix is built for the test geometry"
    sequence = traffic.randomized_mix()
    model = Model(dmd, A.mac, A.ip, A.port)
    for raw, bad in sequence:
        model.frame(raw, bad)
    source = StreamSource(dut, "rx", ByteBeat, dut.clk, seed=3)
    pixels = StreamSink(dut, "pixels", pixel_layout(dmd), dut.clk, stall=0.2, seed=4)
    tx = TxCollector(dut, stall=0.2, seed=5)
    strobes = RegisterCollector(dut)
    feeder = cocotb.start_soon(feed(source, dut, sequence, random.Random(3), (0, 30)))
    got = await with_timeout(pixels.receive(len(model.rows) * dmd.columns), 20, "ms")
    await feeder

    async def replies():
        while len(tx.frames) < len(model.replies):
            await ClockCycles(dut.clk, 100)

    await with_timeout(replies(), 1, "ms")
    await ClockCycles(dut.clk, 2000)      # and nothing more comes
    rows = assemble_rows([(t["frame"], t["row"], t["column"], t["pixels"][0]) for t in got], dmd.columns)
    assert rows == model.rows
    net, app = counters(dut)
    assert net == {k: model.counters[k] for k, _ in records.NET_COUNTERS}
    assert app == {k: model.counters[k] for k, _ in records.APP_COUNTERS}
    assert app["rows_incomplete"] > 0, "the mix breaks some split rows"
    assert strobes.triggers == model.triggers > 0
    assert unpack(layout(records.CONFIG), dut.settings.value.to_unsigned()) == model.config
    assert strobes.sets == [records.registers_bits(wire) for wire in model.registers] and model.registers
    assert strobes.entries == model.entries and model.entries
    assert strobes.starts == model.sequence_starts > 0
    # Status replies and ARP/ICMP replies come from two sources that take turns: the kinds
    # match one for one, the order between the two sources may differ.
    sent = sorted("arp" if ARP in Ether(raw) else "icmp" if ICMP in Ether(raw) else "status" for raw in tx.frames)
    assert sent == sorted(kind for kind, _ in model.replies)
    assert sum(1 for k, _ in model.replies if k == "status") >= 5
