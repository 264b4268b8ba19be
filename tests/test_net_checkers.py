"""Each protocol checker alone, fed frame bytes on its tap, against what scapy reads in the same
frames."""

import random

import pytest
from scapy.layers.inet import ICMP, IP, UDP
from scapy.layers.l2 import ARP, Ether

from gateware.net import arp, ethernet, icmp, ipv4, udp
from sim.harness.amaranth_sim import simulate
from sim.models import frames
from sim.models.net_model import ones_sum

A = frames.Addresses()
RNG = random.Random(8)
FRAMES = [
    frames.udp(A, RNG.randbytes(37)),
    frames.udp(A, b"x" * 3, dst_mac="ff:ff:ff:ff:ff:ff"),
    frames.BAD_FRAMES["bad_ip_checksum"][0](A, b"payload"),
    frames.BAD_FRAMES["bad_udp_checksum"][0](A, b"payload!"),
    frames.BAD_FRAMES["fragment_mf"][0](A, b"frag"),
    frames.BAD_FRAMES["wrong_port"][0](A, b"port"),
    frames.BAD_FRAMES["wrong_dst_mac"][0](A, b"mac"),
    frames.BAD_FRAMES["vlan_tag"][0](A, b"vlan"),
    frames.icmp_echo(A, RNG.randbytes(21)),
    frames.arp_request(A),
    frames.arp_request(A, target="10.0.0.200"),
]


def feed_frames(dut, inputs, read, name, frames_in=FRAMES):
    """Bytes of each frame on ``dut.tap``, then its length; ``read(ctx)`` after each frame."""
    results = []

    async def bench(ctx):
        for port, value in inputs.items():
            ctx.set(getattr(dut, port), value)
        for raw in frames_in:
            for offset, byte in enumerate(raw):
                ctx.set(dut.tap.valid, 1)
                ctx.set(dut.tap.data, byte)
                ctx.set(dut.tap.offset, offset)
                await ctx.tick()
            ctx.set(dut.tap.valid, 0)
            ctx.set(dut.tap.length, len(raw))
            await ctx.tick()
            results.append(read(ctx))

    simulate(dut, [bench], name=name, deadline=1e-3)
    return results


def test_ethernet_checker(test_name):
    dut = ethernet.Checker()
    got = feed_frames(dut, {"mac": A.mac}, lambda ctx: (
        ctx.get(dut.dst_ok), ctx.get(dut.vlan), ctx.get(dut.is_ipv4), ctx.get(dut.is_arp),
        ctx.get(dut.src)), test_name)
    for raw, (dst_ok, vlan, is_ipv4, is_arp, src) in zip(FRAMES, got, strict=True):
        e = Ether(raw)
        assert dst_ok == (e.dst in (A.mac_str, "ff:ff:ff:ff:ff:ff"))
        assert vlan == (e.type == 0x8100) and is_ipv4 == (e.type == 0x0800) and is_arp == (e.type == 0x0806)
        assert src == int(e.src.replace(":", ""), 16)


def test_arp_checker(test_name):
    dut = arp.Checker()
    got = feed_frames(dut, {"ip": A.ip}, lambda ctx: (ctx.get(dut.request_for_us), ctx.get(dut.spa)),
                      test_name)
    for raw, (for_us, spa) in zip(FRAMES, got, strict=True):
        e = Ether(raw)
        if ARP in e:
            assert for_us == (e[ARP].op == 1 and e[ARP].pdst == A.ip_str)
            assert spa == int.from_bytes(bytes(map(int, e[ARP].psrc.split("."))), "big")
        else:
            assert not for_us


def _ipv4_reference(raw):
    head = raw[14:34]
    return {"checksum_ok": ones_sum(head) == 0xFFFF,
            "fragment": bool(head[6] & 0x20 or int.from_bytes(head[6:8], "big") & 0x1FFF),
            "dst_ok": head[16:20] == A.ip.to_bytes(4, "big"),
            "payload_sum_ok": ones_sum(raw[34:14 + int.from_bytes(head[2:4], "big")])}


def test_ipv4_checker(test_name):
    dut = ipv4.Checker()
    got = feed_frames(dut, {"ip": A.ip}, lambda ctx: {
        "length_ok": ctx.get(dut.length_ok), "checksum_ok": ctx.get(dut.checksum_ok),
        "fragment": ctx.get(dut.fragment), "dst_ok": ctx.get(dut.dst_ok),
        "payload_sum": ctx.get(dut.payload_sum), "payload_length": ctx.get(dut.payload_length)},
        test_name)
    for raw, out in zip(FRAMES, got, strict=True):
        e = Ether(raw)
        if IP not in e or e.type != 0x0800:
            continue
        ref = _ipv4_reference(raw)
        assert out["length_ok"] and out["payload_length"] == e[IP].len - 20
        assert (out["checksum_ok"], out["fragment"], out["dst_ok"]) == \
            (ref["checksum_ok"], ref["fragment"], ref["dst_ok"])
        folded = out["payload_sum"]
        while folded >> 16:
            folded = (folded & 0xFFFF) + (folded >> 16)
        assert folded == ref["payload_sum_ok"]


@pytest.mark.parametrize("block", ["icmp", "udp"])
def test_layer4_checkers(block, test_name):
    """ICMP and UDP checkers, given the IPv4 payload sum the IPv4 checker would give them."""
    if block == "icmp":
        dut = icmp.Checker()
        read = lambda ctx: (ctx.get(dut.echo_request), ctx.get(dut.checksum_ok))  # noqa: E731
        inputs = {}
    else:
        dut = udp.Checker()
        read = lambda ctx: (ctx.get(dut.port_ok), ctx.get(dut.checksum_ok), ctx.get(dut.length_ok))  # noqa: E731
        inputs = {"port": A.port}
    results = []
    # one frame per run: the payload sum and length are inputs taken from the reference
    for raw in FRAMES:
        e = Ether(raw)
        if IP not in e or e.type != 0x0800:
            continue
        end = 14 + e[IP].len
        total = sum(int.from_bytes((raw[34:end] + b"\0")[i:i + 2], "big") for i in range(0, end - 34, 2))
        inputs.update({"payload_sum": total, "payload_length": e[IP].len - 20})
        results.append((e, feed_frames(dut, inputs, read, f"{test_name}_{len(results)}", [raw])[0]))
    def raw_of(e):
        return bytes(e)   # the frame as received: padding included, so cut at the IP length

    for e, out in results:
        if block == "icmp" and ICMP in e:
            assert out == (1, 1)
        elif block == "icmp":
            assert out[0] == 0
        elif UDP in e:
            raw_udp = raw_of(e)[34:14 + e[IP].len]
            good_sum = e[UDP].chksum == 0 or ones_sum(
                bytes(map(int, e[IP].src.split("."))) + bytes(map(int, e[IP].dst.split(".")))
                + bytes([0, 17]) + len(raw_udp).to_bytes(2, "big") + raw_udp) == 0xFFFF
            assert out == (int(e[UDP].dport == A.port), int(good_sum), 1), e.summary()
