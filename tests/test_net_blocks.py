"""The stack's parts on their own in the Amaranth simulator: the receive buffer, the transmitter
and the protocol parser, each against a plain Python reference."""

import random

import numpy as np
from scapy.layers.inet import ICMP, IP, UDP
from scapy.layers.l2 import ARP, Ether

from gateware.net.buffer import FrameBuffer
from gateware.net.layouts import ReplyKind
from gateware.net.transmit import Transmitter
from gateware.protocol.parser import Parser, config_init
from host import codec
from sim.harness.amaranth_sim import simulate, stream_collect, stream_put
from sim.models.frames import Addresses
from sim.models.net_model import Model
from sim.tb.endpoint_sim import plain
from spec import records
from spec.facts import TEST_DMD

A = Addresses()


def test_frame_buffer_keeps_committed_frames_only(test_name):
    """Frames written, then kept or forgotten at random; the ring fills and some overflow. What
    is read back is exactly the kept frames, in order."""
    depth = 256
    dut = FrameBuffer(depth)
    rng = random.Random(2)
    plan = [(rng.randbytes(rng.randrange(1, 150)), rng.random() < 0.6) for _ in range(40)]
    kept, got = [], []

    async def writer(ctx):
        pending = []   # (start pointer, length) of kept frames not yet read back
        for data, keep in plan:
            start = ctx.get(dut.frame_start)
            for byte in data:
                ctx.set(dut.write.payload, byte)
                ctx.set(dut.write.valid, 1)
                await ctx.tick()
            ctx.set(dut.write.valid, 0)
            overflow = ctx.get(dut.overflow)
            ctx.set(dut.commit if keep and not overflow else dut.discard, 1)
            await ctx.tick()
            ctx.set(dut.commit, 0)
            ctx.set(dut.discard, 0)
            if keep and not overflow:
                kept.append(data)
                pending.append((start, len(data)))
            # read back every third kept frame, so the ring runs full now and then
            if len(pending) > 2 or data is plan[-1][0]:
                for start, length in pending:
                    await stream_put(ctx, dut.read, {"addr": start, "length": length})
                    got.append(bytes(b["data"] for b in await stream_collect(
                        ctx, dut.data, length, stall=0.3, rng=rng,
                        convert=lambda p: {"data": p.data, "last": p.last})))
                    ctx.set(dut.release_to, (start + length) % (2 * depth))
                    ctx.set(dut.release, 1)
                    await ctx.tick()
                    ctx.set(dut.release, 0)
                pending = []

    simulate(dut, [writer], name=test_name, deadline=1e-3)
    assert got == kept
    assert len(kept) < sum(keep for _, keep in plan), "the ring never overflowed: test too gentle"


def test_transmitter_builds_and_arbitrates(test_name):
    """ARP, ICMP and UDP replies from two sources: whole frames, one source at a time, headers
    as scapy reads them."""
    dut = Transmitter(sources=2)
    peer = {"mac": 0x0200000000AA, "ip": 0x0A000009, "port": 1234}
    icmp_message = bytes(ICMP(type=0, id=7, seq=8) / b"echo")
    udp_payload = b"status!" * 3
    frames_out = []

    async def source(ctx, i, jobs):
        for kind, body in jobs:
            await stream_put(ctx, dut.requests[i], {"kind": kind, "peer": peer, "length": len(body)})
            for j, byte in enumerate(body):
                await stream_put(ctx, dut.bodies[i], {"data": byte, "last": int(j == len(body) - 1)})

    async def src0(ctx):
        ctx.set(dut.mac, A.mac)
        ctx.set(dut.ip, A.ip)
        ctx.set(dut.port, A.port)
        await source(ctx, 0, [(ReplyKind.ARP, b""), (ReplyKind.ICMP, icmp_message)])

    async def src1(ctx):
        await source(ctx, 1, [(ReplyKind.UDP, udp_payload), (ReplyKind.UDP, udp_payload[:5])])

    async def sink(ctx):
        current = bytearray()
        while len(frames_out) < 4:
            beats = await stream_collect(ctx, dut.tx, 1, stall=0.3,
                                         convert=lambda p: (p.data, p.last, p.user))
            data, last, user = beats[0]
            assert not user
            current.append(data)
            if last:
                frames_out.append(bytes(current))
                current = bytearray()

    simulate(dut, [src0, src1, sink], name=test_name, deadline=1e-3)
    parsed = [Ether(f) for f in frames_out]
    assert sorted(("arp" if ARP in p else "icmp" if ICMP in p else "udp") for p in parsed) == \
        ["arp", "icmp", "udp", "udp"]
    for p in parsed:
        assert p.src == A.mac_str and p.dst == "02:00:00:00:00:aa"
        if ARP in p:
            assert p[ARP].op == 2 and p[ARP].psrc == A.ip_str and p[ARP].pdst == "10.0.0.9"
            continue
        assert p[IP].src == A.ip_str and p[IP].dst == "10.0.0.9" and p[IP].flags == "DF"
        ip_sum = p[IP].chksum
        del p[IP].chksum
        assert Ether(bytes(p))[IP].chksum == ip_sum
        if UDP in p:
            assert p[UDP].sport == A.port and p[UDP].dport == 1234
            assert bytes(p[UDP].payload) in (udp_payload, udp_payload[:5])
        else:
            assert bytes(p[ICMP]) == icmp_message


def test_transmitter_addresses_change_mid_frame(test_name):
    """The host changes our addresses while a UDP reply is on its way out (the sink stalls in
    its header): that frame carries the old ones throughout, its IPv4 checksum right; the next
    frame the new ones."""
    dut = Transmitter(sources=2)
    peer = {"mac": 0x0200000000AA, "ip": 0x0A000009, "port": 1234}
    new = {"mac": 0x0200000000BB, "ip": 0x0A000077, "port": 4321}
    frames_out = []

    async def src(ctx):
        ctx.set(dut.mac, A.mac)
        ctx.set(dut.ip, A.ip)
        ctx.set(dut.port, A.port)
        for _ in range(2):
            await stream_put(ctx, dut.requests[0], {"kind": ReplyKind.UDP, "peer": peer, "length": 4})
            for j in range(4):
                await stream_put(ctx, dut.bodies[0], {"data": j, "last": int(j == 3)})

    async def sink(ctx):
        current = bytearray()
        while len(frames_out) < 2:
            data, last = (await stream_collect(ctx, dut.tx, 1, convert=lambda p: (p.data, p.last)))[0]
            current.append(data)
            if len(frames_out) == 0 and len(current) == 20:
                # mid-header (the IPv4 header's first bytes are out): new addresses
                ctx.set(dut.mac, new["mac"])
                ctx.set(dut.ip, new["ip"])
                ctx.set(dut.port, new["port"])
                await ctx.tick().repeat(5)
            if last:
                frames_out.append(bytes(current))
                current = bytearray()

    simulate(dut, [src, sink], name=test_name, deadline=1e-3)
    first, second = (Ether(f) for f in frames_out)
    for p, mac, ip, port in ((first, A.mac_str, A.ip_str, A.port), (second, "02:00:00:00:00:bb", "10.0.0.119", 4321)):
        assert (p.src, p[IP].src, p[UDP].sport) == (mac, ip, port)
        ip_sum = p[IP].chksum
        del p[IP].chksum
        assert Ether(bytes(p))[IP].chksum == ip_sum


def test_parser_against_model(test_name):
    """Records of every kind, good and bad, as datagrams: the pixels of each image record the
    model accepts (with their position, their record's end and first), queries, settings and
    counters as the model says."""
    dmd = TEST_DMD
    dut = Parser(dmd, config_init(mac=A.mac, ip=A.ip, port=A.port))
    model = Model(dmd, A.mac, A.ip, A.port)
    rng = random.Random(4)
    image = np.random.default_rng(4).integers(0, 256, (dmd.rows, dmd.columns), dtype=np.uint8)
    # pieces of the first, a middle and the last rows of the frame: the parser handles each
    # record alone, the others would only lengthen the run
    records_of_image = codec.image_records(image, 9, pixels=1000)
    chosen = [records_of_image[i] for i in (0, len(records_of_image) // 2, -1)]
    datagrams = list(chosen)
    datagrams += [codec.status_query(len(datagrams)), codec.control_record(99, armed=1, bit_depth=4),
                  codec.control_record(100, bit_depth=0), b"\x44\x4d\x03\x01", codec.status_query(5)]
    rng.shuffle(datagrams)
    peer = {"mac": 0x020000000099, "ip": 0x0A000001, "port": 40000}
    pieces = []
    for d in datagrams:
        if model.record(d, peer) == "image":
            _head, body, pixels = codec.decode(d)
            until = body["offset"] + len(pixels)
            pieces += [(body["frame"], body["offset"] + i, byte, until, int(i == 0)) for i, byte in enumerate(pixels)]
    out = {"pieces": [], "queries": []}

    async def feed(ctx):
        for d in datagrams:
            for i, byte in enumerate(d):
                await stream_put(ctx, dut.datagrams, {"data": byte, "last": int(i == len(d) - 1),
                                                      "length": len(d), "peer": peer})
        for _ in range(30):
            await ctx.tick()
        out["app"] = plain(ctx.get(dut.counters), records.RECORD_COUNTERS)
        out["settings"] = plain(ctx.get(dut.settings), records.CONFIG)

    async def pixels(ctx):
        while True:
            p, = await stream_collect(ctx, dut.pieces, 1, stall=0.2, rng=rng)
            out["pieces"].append((p.frame, p.position, p.data, p.until, p.first))

    async def queries(ctx):
        while True:
            q, = await stream_collect(ctx, dut.queries, 1, stall=0.5, rng=random.Random(1))
            out["queries"].append((int(q.sequence), int(q.peer.port)))

    simulate(dut, [feed], processes=[pixels, queries], name=test_name, deadline=1e-3)
    assert out["pieces"] == pieces and len(pieces) == sum(len(r) - records.IMAGE_HEADER for r in chosen)
    assert out["app"] == {k: model.counters[k] for k, _ in records.RECORD_COUNTERS}
    assert out["queries"] == [(r[1]["sequence"], 40000) for r in model.replies]
    assert out["settings"]["armed"] == 1 and out["settings"]["bit_depth"] == 4
