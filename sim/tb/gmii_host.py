"""A host on a core's GMII pins, for cocotb testbenches: sends scapy-built datagrams with
preamble and FCS, collects the frames the core transmits (preamble and FCS checked), and asks
for status replies.

The core's ports, as Amaranth's Verilog names them: ``gmii_rx`` (a packed
:class:`gateware.mac.gmii.RxPins`: ``d | dv << 8 | er << 9``), ``gmii_tx`` (a packed
:class:`~gateware.mac.gmii.TxPins`), the clocks ``gmii_rx_clk``, ``gmii_tx_clk`` and ``clk``
(``sync``), which the testbench starts.
"""

import zlib

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, FallingEdge, RisingEdge, Timer
from cocotb.utils import get_sim_time
from scapy.layers.inet import IP, UDP
from scapy.layers.l2 import Ether
from scapy.packet import Raw

from gateware.mac.gmii import TxPins
from host import codec
from sim.harness.layout import fields
from sim.models import gmii_stim as gmii
from spec import records

__all__ = ["GmiiHost", "HOST_MAC", "HOST_IP", "HOST_PORT", "address_value", "start_clocks"]

HOST_MAC, HOST_IP, HOST_PORT = "02:00:00:00:00:99", "10.0.0.1", 40000


def address_value(text):
    """A MAC (``02:00:...``) or IPv4 (``10.0.0.1``) address as text -> its value."""
    return int(text.replace(":", ""), 16) if ":" in text else int.from_bytes(bytes(map(int, text.split("."))), "big")


async def start_clocks(dut, periods_ns, *, held=4):
    """Start ``dut``'s clocks (``{"clk": ns, "gmii_rx_clk": ns, ...}``), each a quarter
    nanosecond after the one before (so that no two domains' edges coincide), with each domain's
    reset (``rst`` for ``clk``, ``<domain>_rst`` for ``<domain>_clk``) held until ``held`` cycles
    of the first have passed. Returns each clock's start time in picoseconds (its first rising
    edge)."""
    resets = [getattr(dut, "rst" if name == "clk" else name[:-len("clk")] + "rst") for name in periods_ns]
    for rst in resets:
        rst.value = 1
    started = {}
    for i, (name, ns) in enumerate(periods_ns.items()):
        if i:
            await Timer(250, "ps")
        started[name] = round(get_sim_time("ps"))
        cocotb.start_soon(Clock(getattr(dut, name), ns, unit="ns").start())
    await ClockCycles(getattr(dut, next(iter(periods_ns))), held)
    for rst in resets:
        rst.value = 0
    return started


class GmiiHost:
    """The host's side of the GMII pins of ``dut``, whose addresses are ``mac``, ``ip``,
    ``port`` (text, as scapy takes them; ``port`` an int).

    Attributes
    ----------
    net : object or None
        A reference model that sees each frame sent as the MAC will (``net.frame(frame, bad)``).
    frames_sent : int
    mac : dict
        Frames sent per the MAC's verdict to come (``good``, ``bad_fcs``).
    sequence : int
        The host's record counter, as :class:`host.Client` keeps it.
    replies : list of bytes
        UDP payloads of frames on the transmit pins.
    tx_frames : list of bytes
        Every frame on the transmit pins (no FCS).
    """

    def __init__(self, dut, mac, ip, port, *, net=None):
        self.dut, self.address = dut, (mac, ip, port)
        self.net = net
        self.frames_sent = 0
        self.mac = {"good": 0, "bad_fcs": 0}
        self.sequence = 0
        self.replies = []
        self.tx_frames = []

    def listen(self):
        """Start collecting the transmitted frames (once the clocks run)."""
        cocotb.start_soon(self._receive_tx())

    async def _receive_tx(self):
        """Frames on the GMII transmit pins: preamble and SFD stripped, FCS checked. The pins
        are registered on the transmit clock: sampled mid-cycle (falling edge) every cycle of a
        frame, and between frames only once they change."""
        pins, edge, frame = self.dut.gmii_tx, FallingEdge(self.dut.gmii_tx_clk), bytearray()
        tx = {name: (offset, mask) for name, offset, mask in fields(TxPins)}
        (d, d_mask), (en, _), (er, _) = tx["d"], tx["en"], tx["er"]
        while True:
            await edge
            value = pins.value.to_unsigned()
            assert not value >> er & 1, "tx_er on the transmit pins"
            if value >> en & 1:
                frame.append(value >> d & d_mask)
                continue
            if frame:
                assert frame[:8] == gmii.PREAMBLE, "preamble or SFD wrong"
                body = bytes(frame[8:])
                assert zlib.crc32(body) == 0x2144DF1C, "bad FCS on a transmitted frame"
                self.tx_frames.append(body[:-4])
                packet = Ether(body[:-4])
                if UDP in packet:
                    self.replies.append(bytes(packet[UDP].payload))
                frame = bytearray()
            await pins.value_change

    def datagram(self, payload, *, port=None):
        """An Ethernet frame (no FCS) carrying ``payload`` from the host to the core's port (or ``port``)."""
        mac, ip, own = self.address
        return bytes(Ether(src=HOST_MAC, dst=mac) / IP(src=HOST_IP, dst=ip)
                     / UDP(sport=HOST_PORT, dport=own if port is None else port) / Raw(payload))

    def next_sequence(self, count=1):
        first, self.sequence = self.sequence, self.sequence + count
        return first

    async def send(self, frames, bad_fcs=()):
        """Drive GMII with ``frames`` (Ethernet frames, no FCS): preamble, FCS (corrupted for the
        indices in ``bad_fcs``), minimum gaps. The reference model sees each as the MAC will."""
        edge = RisingEdge(self.dut.gmii_rx_clk)
        self.frames_sent += len(frames)
        for i, frame in enumerate(frames):
            wire = bytearray(gmii.wire_bytes(frame))
            bad = i in bad_fcs
            if bad:
                wire[-1] ^= 0x40
            self.mac["bad_fcs" if bad else "good"] += 1
            if self.net is not None:
                self.net.frame(frame, bad)
            for byte in gmii.PREAMBLE + bytes(wire):
                await edge
                self.dut.gmii_rx.value = byte | (1 << 8)
            for _ in range(gmii.MIN_GAP):
                await edge
                self.dut.gmii_rx.value = 0

    async def status(self, kind=records.RecordType.STATUS_REPLY, *, waits=200, cycles=100):
        """Ask for a status reply over GMII; its fields as a dict (a reply of type ``kind``
        with the query's sequence number, within ``waits`` x ``cycles`` ``sync`` cycles)."""
        sequence = self.next_sequence()
        count = len(self.replies)
        await self.send([self.datagram(codec.status_query(sequence))])
        for _ in range(waits):
            await ClockCycles(self.dut.clk, cycles)
            for raw in self.replies[count:]:
                head, body, _rest = codec.decode(raw)
                if head["type"] == kind and head["sequence"] == sequence:
                    return body
        raise AssertionError("no status reply on the transmit pins")
