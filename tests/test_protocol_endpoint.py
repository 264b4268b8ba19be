"""The endpoint (network stack + protocol parser + status reply) in the Amaranth simulator.

Frames are built by scapy and the host encoder (:mod:`sim.models.endpoint_traffic`); expectations
come from the reference model in :mod:`sim.models.net_model`; replies are parsed back by scapy. The
long runs (the randomized mix with its ledger, records back to back at line rate) run on the
generated Verilog (:mod:`sim.tb.endpoint_tb`, ``tests/test_protocol_endpoint_verilog.py``).
"""

import pytest
from scapy.layers.inet import ICMP, IP, UDP
from scapy.layers.l2 import ARP, Ether

from host import codec
from sim.models import frames
from sim.models.endpoint_traffic import BAD_CASES, GOOD_WIRE, IMAGE, A, image_frame, sequencer_record
from sim.models.frames import Addresses
from sim.models.net_model import Model
from sim.tb import endpoint_sim
from spec import records
from spec.facts import TEST_DMD
from spec.registers import PlaneOrder


@pytest.fixture(scope="module")
def one_by_one():
    """Every bad frame, each between good image records, with a snapshot after every frame."""
    sequence = [(image_frame(0), False)]
    sequence += [(raw, bad) for raw, bad, _counter in BAD_CASES.values()]
    sequence.append((image_frame(1, frame=1), False))
    out = endpoint_sim.run(sequence, name="endpoint_bad_one_by_one", settle_each=200, gap=(0, 20))
    return sequence, out


def _delta(before, after, table):
    return {name: after[name] - before[name] for name, _ in table}


@pytest.mark.parametrize("case", list(BAD_CASES))
def test_bad_frame_dropped_and_counted(case, one_by_one):
    sequence, out = one_by_one
    index = 1 + list(BAD_CASES).index(case)
    before, after = out["snapshots"][index - 1], out["snapshots"][index]
    counter = BAD_CASES[case][2]
    table = records.NET_COUNTERS if counter in dict(records.NET_COUNTERS) else records.APP_COUNTERS
    other = records.APP_COUNTERS if table is records.NET_COUNTERS else records.NET_COUNTERS
    delta = _delta(before["net" if table is records.NET_COUNTERS else "app"],
                   after["net" if table is records.NET_COUNTERS else "app"], table)
    expected = {name: 0 for name, _ in table}
    expected[counter] = 1
    if table is records.NET_COUNTERS:
        expected["frames"] = 1
        other_delta = _delta(before["app"], after["app"], other)
        assert not any(other_delta.values()), f"a dropped frame reached the protocol: {other_delta}"
    else:
        net_delta = _delta(before["net"], after["net"], other)
        assert net_delta["frames"] == net_delta["accepted"] == 1
    assert delta == expected
    assert after["pixel_count"] == before["pixel_count"], "pixels of a dropped frame leaked"
    assert after["register_count"] == before["register_count"], "registers of a dropped record were handed on"
    assert after["entry_count"] == before["entry_count"], "an entry of a dropped record was handed on"
    assert after["config"] == before["config"], "a dropped record changed the configuration"
    assert after["tx_count"] == before["tx_count"], "a dropped frame was answered"
    # The reference model names the same cause.
    model = Model(TEST_DMD, A.mac, A.ip, A.port)
    raw, bad, _ = BAD_CASES[case]
    outcome = model.frame(raw, bad)
    if outcome == "udp":
        outcome = next(name for name, value in model.counters.items()
                       if name.startswith("drop_app") and value)
    assert outcome == counter


def test_padding_beyond_the_ip_length_is_trimmed(test_name):
    """Frames longer than their IP total length (RFC 894 / RFC 1122 padding, or a NIC's extra
    bytes): the datagram is the total length's bytes, the rest is not part of it."""
    echo = frames.icmp_echo(A, bytes(range(30)), ident=7, seq=2)
    sequence = [(image_frame(0) + b"\xa5" * 17, False), (echo + bytes(40), False),
                (image_frame(1) + b"\x01", False)]
    out = endpoint_sim.run(sequence, name=test_name, gap=(12, 12), waves=False)
    assert out["net"]["accepted"] == 3 and out["net"]["drop_ip_length"] == 0
    assert [(r, d) for _f, r, d in out["rows"]] == [(0, IMAGE[0].tobytes()), (1, IMAGE[1].tobytes())]
    reply = Ether(out["tx"][0])
    assert bytes(reply[ICMP].payload) == bytes(range(30)) and reply[IP].len == 20 + 8 + 30


def test_good_frames_around_bad_ones_arrive(one_by_one):
    sequence, out = one_by_one
    assert [(r, data) for _f, r, data in out["rows"]] == [(0, IMAGE[0].tobytes()), (1, IMAGE[1].tobytes())]


@pytest.fixture(scope="module")
def replies():
    """ARP, ICMP echo, a status query and control records, in one run."""
    new_ip, new_port = 0x0A_00_00_33, 6001
    control = codec.control_record(1, bit_depth=6, armed=1, sequence_length=5, software_trigger=True)
    registers = [sequencer_record(5), sequencer_record(6, order=PlaneOrder.LSB_FIRST.value, chain=1)]
    readdress = codec.control_record(2, ip=new_ip, port=new_port)
    moved = Addresses(ip=new_ip, port=new_port)
    status = {"uptime_cycles": 123456789, "clock_hz": 125_000_000, "triggers": 7,
              "trigger_overruns": 1, "frames_shown": 6, "dlpc410_state": 0b101}
    sequence = [
        (frames.arp_request(A), False),
        (frames.icmp_echo(A, bytes(range(40)), ident=0x4242, seq=9), False),
        (frames.udp(A, control), False),
        (frames.udp(A, codec.status_query(77)), False),
        (frames.udp(A, readdress), False),
        (frames.arp_request(moved), False),
        (frames.udp(A, codec.status_query(3)), False),         # old address: dropped
        (frames.udp(Addresses(ip=new_ip), codec.status_query(4)), False),  # old port: dropped
        (frames.udp(moved, codec.status_query(78)), False),
        (frames.udp(moved, registers[0]), False),
        (frames.udp(moved, registers[1]), False),
    ]
    out = endpoint_sim.run(sequence, name="endpoint_replies", settle_each=80, gap=(5, 5),
                         status=status)
    return out, status, moved


def test_arp_request_answered(replies):
    out, _, moved = replies
    for raw, ip in ((out["tx"][0], A.ip_str), (out["tx"][3], moved.ip_str)):
        reply = Ether(raw)
        assert reply.dst == A.host_mac and reply.src == A.mac_str
        assert reply[ARP].op == 2 and reply[ARP].hwsrc == A.mac_str and reply[ARP].psrc == ip
        assert reply[ARP].hwdst == A.host_mac and reply[ARP].pdst == A.host_ip


def test_icmp_echo_answered(replies):
    out = replies[0]
    reply = Ether(out["tx"][1])
    assert reply.dst == A.host_mac and reply[IP].src == A.ip_str and reply[IP].dst == A.host_ip
    assert reply[ICMP].type == 0 and reply[ICMP].id == 0x4242 and reply[ICMP].seq == 9
    assert bytes(reply[ICMP].payload) == bytes(range(40))
    # checksums as scapy computes them
    ip_sum, icmp_sum = reply[IP].chksum, reply[ICMP].chksum
    del reply[IP].chksum, reply[ICMP].chksum
    rebuilt = Ether(bytes(reply))
    assert rebuilt[IP].chksum == ip_sum and rebuilt[ICMP].chksum == icmp_sum


def test_control_record_applied(replies):
    out = replies[0]
    before, after = out["snapshots"][1], out["snapshots"][2]
    assert after["triggers"] - before["triggers"] == 1
    config = after["config"]
    assert (config["bit_depth"], config["armed"], config["sequence_length"]) == (6, 1, 5)
    assert config["mac"] == A.mac and config["ip"] == A.ip   # not selected: unchanged
    assert out["config"]["ip"] == 0x0A_00_00_33 and out["config"]["port"] == 6001


def test_sequencer_records_handed_on_whole(replies):
    """Each valid sequencer record leaves as one register set, every field as sent."""
    out = replies[0]
    second = {**GOOD_WIRE, "order": PlaneOrder.LSB_FIRST.value, "chain": 1}
    assert out["registers"] == [records.registers_bits(GOOD_WIRE), records.registers_bits(second)]
    assert out["app"]["records_sequencer"] == 2


def test_status_query_answered(replies):
    out, status, moved = replies
    assert len(out["tx"]) == 5   # ARP, ICMP, status, ARP at the new address, status at the new port
    for raw, sequence, ip, port in ((out["tx"][2], 77, A.ip_str, A.port),
                                    (out["tx"][4], 78, moved.ip_str, moved.port)):
        reply = Ether(raw)
        assert reply[IP].src == ip and reply[IP].dst == A.host_ip
        assert reply[UDP].sport == port and reply[UDP].dport == A.host_port
        ip_sum = reply[IP].chksum
        del reply[IP].chksum
        assert Ether(bytes(reply))[IP].chksum == ip_sum
        head, body, rest = codec.decode(bytes(reply[UDP].payload))
        assert head["type"] == records.RecordType.STATUS_REPLY and head["sequence"] == sequence
        assert rest == b""
        assert {k: body[k] for k in status} == status
    first = codec.decode(bytes(Ether(out["tx"][2])[UDP].payload))[1]
    assert first["records_control"] == 1 and first["records_status"] == 1
    assert first["arp_replies"] == 1 and first["icmp_replies"] == 1
    assert out["net"]["drop_ip_dst"] == 1 and out["net"]["drop_udp_port"] == 1


def test_buffer_overflow_drops_whole_frames(test_name):
    """A consumer far slower than the line: frames that find no room are dropped whole and
    counted; every row that does come out is complete and belongs to an accepted record."""
    sequence = [(image_frame(r, rows=2, sequence=r), False) for r in range(0, 24, 2)]
    out = endpoint_sim.run(sequence, name=test_name, gap=(0, 0), pixel_stall=0.9, buffer_depth=1024,
                         waves=False)
    net = out["net"]
    assert net["drop_overflow"] > 0
    assert net["frames"] == net["accepted"] + net["drop_overflow"] == len(sequence)
    assert len(out["rows"]) == 2 * net["accepted"] == out["app"]["rows"]
    assert all(d == IMAGE[r].tobytes() for _f, r, d in out["rows"])
