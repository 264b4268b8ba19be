"""The simulation's fast GMII stimulus: file writer (against scapy and zlib) and Verilog replay
(:mod:`sim.tb.gmii_replay_tb`)."""

import zlib

import pytest
from scapy.layers.inet import IP, UDP
from scapy.layers.l2 import Ether
from scapy.packet import Raw

from sim.harness import cocotb_run
from sim.harness.paths import ROOT, build_dir
from sim.models import gmii_stim as gmii


def frames():
    return [bytes(Ether(dst="02:00:00:00:00:01") / IP(dst="10.0.0.2") / UDP(dport=5000) / Raw(b"x" * n))
            for n in (1, 100, 1400)]


def test_wire_bytes_pad_and_fcs():
    short = frames()[0]
    wire = gmii.wire_bytes(short)
    assert len(wire) == 64
    # a frame followed by its FCS has the CRC-32 residue
    assert zlib.crc32(wire) & 0xFFFFFFFF == 0x2144DF1C


def test_cycles_layout():
    fs = frames()
    stream = gmii.cycles(fs, errors={(1, 20): True})
    assert len(stream) == sum(8 + max(60, len(f)) + 4 + 12 for f in fs)
    assert [c[2] for c in stream[:8]] == list(gmii.PREAMBLE)
    first_gap = 8 + 64
    assert stream[first_gap:first_gap + 12] == [(0, 0, 0)] * 12
    assert sum(c[1] for c in stream) == 1


@pytest.mark.verilog
def test_replay_verilog():
    fs = frames()
    path = build_dir("cocotb", "gmii_replay-frames") / "frames.bin"
    gmii.replay_file(path, fs, errors={(2, 30): True})
    cocotb_run.run(None, toplevel="gmii_replay", module="sim.tb.gmii_replay_tb", key="frames",
                   extra_sources=[ROOT / "sim" / "hdl" / "gmii_replay.v"],
                   plusargs=[f"+GMII_REPLAY={path}"],
                   params={"cycles": gmii.cycles(fs, errors={(2, 30): True})})
