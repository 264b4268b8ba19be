"""cocotb testbench of the whole Ethernet side (:class:`gateware.protocol.port.EthernetPort`) on its
generated Verilog: GMII pins in, image rows, counters and GMII replies out.

cocotbext-eth's ``GmiiSource`` drives the receive pins (frames built by scapy and the host encoder),
``GmiiSink`` reads the transmit pins. What must come out is predicted by chaining the reference
models: :func:`sim.models.mac_model.receive` makes of the GMII symbols what the receive MAC must
hand on, and :class:`sim.models.net_model.Model` what the stack and protocol must do with that.
Three clocks, none sharing edges with another: ``gmii_rx`` 8 ns, ``gmii_tx`` 8 ns shifted by 0.3 ns,
``sync`` 7.5 ns (133 MHz) by default.

Run by ``tests/test_ethernet_verilog.py``.
"""

import logging
import random

import cocotb
import numpy as np
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, RisingEdge, Timer, with_timeout
from cocotb.utils import get_sim_time
from cocotbext.eth import GmiiFrame, GmiiSink, GmiiSource

from gateware.mac.gmii_rx import counters_layout
from gateware.protocol.layouts import pixel_layout
from gateware.wire import layout
from host import codec
from sim.harness.cocotb_run import params
from sim.harness.layout import pack, unpack
from sim.models import frames
from sim.models import mac_model as mac
from sim.models.net_model import Model
from sim.tb.endpoint_sim import assemble_rows
from sim.tb.endpoint_tb import check_replies
from sim.tb.mac_rx_tb import symbols_of
from spec import records, wire
from spec.facts import DMDS

A = frames.Addresses()
GMII_PS = 8000
CLOCK_HZ = 125_000_000


class Bench:
    """The port after a reset: a GMII source on the receive pins, a GMII sink on the transmit
    pins, and a consumer of ``pixels`` that is always ready (or stalls with ``stall``)."""

    def __init__(self, dut, dmd, sync_ps, stall, sink):
        self.dut, self.dmd, self.sync_ps = dut, dmd, sync_ps
        self.source = GmiiSource(dut.gmii_rxd, dut.gmii_rx_er, dut.gmii_rx_dv, dut.gmii_rx_clk)
        self.sink = GmiiSink(dut.gmii_txd, dut.gmii_tx_er, dut.gmii_tx_en, dut.gmii_tx_clk) if sink else None
        for driver in (self.source, self.sink):
            if driver:
                driver.log.setLevel(logging.WARNING)  # not every frame in the log
        # (offset, mask) of each pixel field: decoded by hand, every sync cycle counts
        self._fields = [(f.offset, (1 << f.width) - 1) for name in ("frame", "row", "column", "pixels")
                        for f in [pixel_layout(dmd)[name]]]
        self.pixels = []          # (frame, row, column, value)
        self.row_starts = []      # sim time (ps) of the transfer of each row's first pixel
        self.last_pixel = 0
        self._stall, self._rng = stall, random.Random(9)
        cocotb.start_soon(self._take_pixels())

    @classmethod
    async def start(cls, dut, *, sync_ps=7500, stall=0.0, sink=True):
        dmd = DMDS[params()["dmd"]]
        cocotb.start_soon(Clock(dut.gmii_rx_clk, GMII_PS, unit="ps").start())
        await Timer(300, unit="ps")
        cocotb.start_soon(Clock(dut.gmii_tx_clk, GMII_PS, unit="ps").start())
        await Timer(400, unit="ps")
        cocotb.start_soon(Clock(dut.clk, sync_ps, unit="ps").start())
        dut.status.value = pack(layout(records.SYSTEM_STATUS), {"clock_hz": CLOCK_HZ})
        dut.registers__ready.value = 1
        for rst in (dut.rst, dut.gmii_rx_rst, dut.gmii_tx_rst):
            rst.value = 1
        await ClockCycles(dut.clk, 4)
        for rst in (dut.rst, dut.gmii_rx_rst, dut.gmii_tx_rst):
            rst.value = 0
        await ClockCycles(dut.clk, 4)
        return cls(dut, dmd, sync_ps, stall, sink)

    async def _take_pixels(self):
        dut = self.dut
        edge, driven = RisingEdge(dut.clk), None
        while True:
            ready = not (self._stall and self._rng.random() < self._stall)
            if ready != driven:
                dut.pixels__ready.value = driven = ready
            if not self._stall and not dut.pixels__valid.value:
                # always ready and nothing offered: no cycle to look at until valid rises
                await RisingEdge(dut.pixels__valid)
            await edge
            if ready and dut.pixels__valid.value:
                bits = dut.pixels__payload.value.to_unsigned()
                pixel = tuple(bits >> offset & mask for offset, mask in self._fields)
                self.pixels.append(pixel)
                self.last_pixel = get_sim_time("ps")
                if pixel[2] == 0:
                    self.row_starts.append(self.last_pixel)

    async def send(self, gmii_frames, timeout_ms=20):
        for frame in gmii_frames:
            await self.source.send(frame)
        await with_timeout(self.source.wait(), timeout_ms, "ms")


    async def settle(self, quiet_ps=10_000_000):
        """Wait until no pixel and no transmitted byte for ``quiet_ps``."""
        quiet_since = get_sim_time("ps")
        while True:
            await ClockCycles(self.dut.clk, 64)
            now = get_sim_time("ps")
            if self.dut.gmii_tx_en.value or (self.sink and not self.sink.idle()):
                quiet_since = now
            if now - max(quiet_since, self.last_pixel) >= quiet_ps:
                return

    def rows(self):
        return assemble_rows(self.pixels, self.dmd.columns)

    def transmitted(self):
        """Frames on the transmit pins, destination MAC to payload, each checked for a whole
        preamble with SFD, no ``tx_er`` and a good FCS."""
        out = []
        while self.sink and not self.sink.empty():
            frame = self.sink.recv_nowait()
            assert frame.error is None and frame.get_preamble()[-1] == 0xD5 and frame.check_fcs()
            out.append(bytes(frame.get_payload()))
        return out

    def counters(self):
        dut = self.dut
        return {
            "mac": unpack(counters_layout(), dut.mac_counters.value.to_unsigned()),
            "net": unpack(layout(records.NET_COUNTERS), dut.net_counters.value.to_unsigned()),
            "app": unpack(layout(records.APP_COUNTERS), dut.app_counters.value.to_unsigned()),
            "rx_dropped": int(dut.rx_dropped.value),
            "tx_underruns": int(dut.tx_underruns.value),
        }


def gmii(frame):
    """A frame (destination MAC to payload) as the host NIC sends it: FCS appended, standard
    preamble."""
    return GmiiFrame.from_raw_payload(mac.with_fcs(frame))


def predict(dmd, gmii_frames):
    """The models' view of ``gmii_frames`` sent back to back at the minimum gap: the receive
    MAC's results, then the stack and protocol fed with what the MAC hands on."""
    symbols = []
    for f in gmii_frames:
        symbols += symbols_of(f) + mac.idle(12)
    received = mac.receive(symbols)
    model = Model(dmd, A.mac, A.ip, A.port)
    for r in received:
        if r.data:
            model.frame(r.data, r.bad)
    return received, model


async def expect(bench, gmii_frames):
    """Send back to back; rows, every counter and every reply as the models predict."""
    received, model = predict(bench.dmd, gmii_frames)
    await bench.send(gmii_frames)
    await bench.settle()
    assert bench.rows() == model.rows
    got = bench.counters()
    assert got["mac"] == mac.counts(received)
    assert got["net"] == {k: model.counters[k] for k, _ in records.NET_COUNTERS}
    assert got["app"] == {k: model.counters[k] for k, _ in records.APP_COUNTERS}
    assert got["rx_dropped"] == 0 and got["tx_underruns"] == 0
    check_replies(bench.transmitted(), model)
    return model, got


def image(dmd, seed):
    return np.random.default_rng(seed).integers(0, 256, (dmd.rows, dmd.columns), dtype=np.uint8)


def image_frames(picture, frame, rows_per_record, rows, *, pixels=None):
    """Rows ``0 .. rows - 1`` of ``picture`` in records of ``rows_per_record`` whole rows (or of
    ``pixels`` pixels, splitting rows)."""
    step = pixels or rows_per_record * picture.shape[1]
    return [frames.udp(A, r) for r in codec.image_records(picture[:rows], frame, pixels=step)]


@cocotb.test()
async def good_traffic_back_to_back(dut):
    """Image records of 1 and 3 rows and of 1,462 pixels (a 1500-byte MTU's, rows split), ICMP
    echoes of random size, ARP, status queries and 9,018-byte frames for another port, back to
    back at the minimum gap: 64 to 9,018 bytes on the line. Every row arrives intact, every reply
    is right, nothing is dropped for room."""
    bench = await Bench.start(dut)
    rng = random.Random(11)
    picture = image(bench.dmd, 1)
    good = (image_frames(picture, 1, 1, 12) + image_frames(picture, 2, 3, 12)
            + image_frames(picture, 3, None, 24, pixels=codec.pixels_per_record(records.record_limit(1500))))
    others = [frames.icmp_echo(A, rng.randbytes(rng.randint(18, 1472)), seq=i) for i in range(4)]
    others += [frames.arp_request(A), frames.udp(A, codec.status_query(7))]
    others += [frames.udp(A, rng.randbytes(8972), dport=A.port + 1) for _ in range(2)]
    traffic = list(good)
    for raw in others:
        traffic.insert(rng.randrange(len(traffic) + 1), raw)
    gmii_frames = [gmii(raw) for raw in traffic]
    sizes = [len(f.get_payload()) + 4 for f in gmii_frames]
    assert min(sizes) == 64 and max(sizes) == 9018
    model, got = await expect(bench, gmii_frames)
    assert got["app"]["records_image"] == len(good) and len(model.rows) == 48
    assert got["net"]["drop_udp_port"] == 2


@cocotb.test()
async def replies(dut):
    """ARP request, ICMP echo and status query: each reply read back by scapy from the pins."""
    bench = await Bench.start(dut)
    traffic = [frames.arp_request(A), frames.icmp_echo(A, b"projector" * 8),
               frames.udp(A, codec.status_query(42))]
    model, got = await expect(bench, [gmii(raw) for raw in traffic])
    assert [kind for kind, _ in model.replies] == ["arp", "icmp", "status"]
    assert got["net"]["arp_replies"] == got["net"]["icmp_replies"] == 1


def _with_header(record, **changes):
    """``record`` (from the host encoder) with header fields changed."""
    size = wire.size(records.HEADER)
    head = {**wire.unpack(records.HEADER, record[:size]), **changes}
    return wire.pack(records.HEADER, head) + record[size:]


def _with_image_fields(record, **changes):
    size, end = wire.size(records.HEADER), records.IMAGE_HEADER
    body = {**wire.unpack(records.IMAGE, record[size:end]), **changes}
    return record[:size] + wire.pack(records.IMAGE, body) + record[end:]


def _as_delta(record, carried):
    """``record`` (a whole frame's image record) as a delta record of the same pixels."""
    size, end = wire.size(records.HEADER), records.IMAGE_HEADER
    head = {**wire.unpack(records.HEADER, record[:size]), "type": records.RecordType.DELTA}
    body = {**wire.unpack(records.IMAGE, record[size:end]), "base": 0, "carried": carried}
    return wire.pack(records.HEADER, head) + wire.pack(records.DELTA, body) + record[end:]


def bad_frames(dmd, record):
    """One GMII frame per class of bad input, with the counter that must count it:
    ``[(name, GmiiFrame, (counter group, counter))]``."""
    out = []
    fcs = bytearray(mac.with_fcs(frames.udp(A, record)))
    fcs[-1] ^= 0x40
    out.append(("bad_fcs", GmiiFrame.from_raw_payload(bytes(fcs)), ("mac", "bad_fcs")))
    for name, at in (("rx_er_start", 8), ("rx_er_middle", 8 + 500), ("rx_er_in_fcs", -2)):
        frame = gmii(frames.udp(A, record))
        frame.normalize()
        frame.error[at] = 1
        out.append((name, frame, ("mac", "rx_er")))
    out.append(("runt", GmiiFrame.from_raw_payload(mac.with_fcs(frames.udp(A, b"")[:40])), ("mac", "runt")))
    for name, (builder, counter) in frames.BAD_FRAMES.items():
        out.append((name, gmii(builder(A, record)), ("net", counter)))
    malformed = {
        "unknown_version": (_with_header(record, version=records.VERSION + 1), "drop_app_version"),
        "image_without_pixels": (record[:records.IMAGE_HEADER], "drop_app_empty"),
        "truncated_header": (record[:wire.size(records.HEADER) - 1], "drop_app_length"),
        "pixels_beyond_frame": (_with_image_fields(record, offset=dmd.rows * dmd.columns - 1), "drop_app_rows"),
        "delta_without_rows": (_as_delta(record, carried=0), "drop_app_value"),
    }
    for name, (bad, counter) in malformed.items():
        out.append((name, gmii(frames.udp(A, bad)), ("app", counter)))
    return out


@cocotb.test()
async def bad_frames_counted_by_cause(dut):
    """Each class of bad frame between good image records at the minimum gap: counted under
    its own cause (MAC verdict or stack/protocol drop), and no byte of it handed on."""
    bench = await Bench.start(dut)
    dmd = bench.dmd
    picture = image(dmd, 2)
    rows_per_record = 2
    bad = bad_frames(dmd, codec.image_records(picture[:rows_per_record], 6, pixels=rows_per_record * dmd.columns)[0])
    good = [gmii(f) for f in image_frames(picture, 5, rows_per_record, (len(bad) + 2) * rows_per_record)]
    traffic = []
    for i, (_name, frame, _cause) in enumerate(bad):
        traffic += [good[i], frame]
    traffic += good[len(bad):]
    model, got = await expect(bench, traffic)
    # The models agree with the hardware (checked in expect); here: each bad frame under its cause.
    expected = {}
    for _name, _frame, cause in bad:
        expected[cause] = expected.get(cause, 0) + 1
    for (group, counter), count in expected.items():
        assert got[group][counter] == count, (group, counter, got[group][counter], count)
    mac_bad = sum(n for (group, _), n in expected.items() if group == "mac")
    assert got["net"]["drop_mac"] == mac_bad and got["mac"]["good"] == len(traffic) - mac_bad
    # Nothing leaks: exactly the good records' rows, in order.
    assert got["app"]["records_image"] == len(good)
    want = [(5, r, picture[r].tobytes()) for r in range(len(good) * rows_per_record)]
    assert bench.rows() == want


@cocotb.test()
async def stalling_consumer(dut):
    """The pixel consumer holds ready low 60 % of the time, so it cannot keep up with the line:
    records that arrive are intact, and every other record is dropped whole and counted (by the
    receive FIFO or the stack's ring)."""
    bench = await Bench.start(dut, stall=0.6, sink=False)
    picture = image(bench.dmd, 3)
    traffic = [gmii(f) for f in image_frames(picture, 7, 8, 64)]
    await bench.send(traffic)
    await bench.settle()
    got = bench.counters()
    rows = bench.rows()
    assert all(data == picture[r].tobytes() for _f, r, data in rows)
    lost = got["rx_dropped"] + got["net"]["drop_overflow"]
    assert got["app"]["records_image"] * 8 == len(rows)
    assert got["app"]["records_image"] + lost == len(traffic), (got, len(rows))
    assert lost > 0 and got["mac"]["good"] == len(traffic)
