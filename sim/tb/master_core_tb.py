"""cocotb testbench of the sync master's core (:class:`gateware.top.sync_master.SyncMasterCore`,
its generated Verilog) driven over GMII as a host drives it.

Every record is built here from the protocol's tables inside a scapy datagram; the reference
model (:class:`sim.models.master_net_model.MasterModel`, written from the protocol page) sees each
frame and predicts the configuration and every counter of the master status reply. A monitor
reads the sync and camera lines every cycle: every pulse on every board's line at once, on the
camera line with them, ``width`` cycles long.

The run: the power-up status; a pin trigger while disarmed (nothing); software triggers by
record (one pulse each), one too soon (``early``), one with a board not ready (``not_ready``);
records the master must drop (each cause, every bad value, each with the trigger action: no
pulse, nothing applied), one to another UDP port, one with a sequence gap; the periodic mode
(the pulses ``period`` apart); the trigger pin; the button. The status reply then equals the
model's, field by field.

Run by ``tests/test_sync_master_port.py``.
"""

import cocotb
from cocotb.triggers import ClockCycles, FallingEdge, ReadOnly, RisingEdge

from host import codec
from sim.harness.cocotb_run import params
from sim.models.master_net_model import MasterModel
from sim.tb.gmii_host import GmiiHost, address_value, start_clocks
from spec import records, wire
from spec.records import Action, RecordType
from spec.registers import TriggerMode

NS = 8.0



class Pulses:
    """The sync and camera lines, read every ``sync`` cycle: each pulse's first cycle and length."""

    def __init__(self, dut, boards):
        self.dut, self.all = dut, (1 << boards) - 1
        self.cycle = 0
        self.starts, self.widths = [], []

    async def run(self):
        dut, high = self.dut, 0
        while True:
            await RisingEdge(dut.clk)
            await ReadOnly()
            self.cycle += 1
            lines = dut.sync_out.value.to_unsigned()
            assert lines in (0, self.all), f"cycle {self.cycle}: sync lines {lines:b}, not all at once"
            assert bool(lines) == bool(dut.camera_out.value), f"cycle {self.cycle}: camera apart from the sync lines"
            if lines:
                if not high:
                    self.starts.append(self.cycle)
                high += 1
            elif high:
                self.widths.append(high)
                high = 0


class Host(GmiiHost):
    """The master's host: master control records as ``docs/protocol.md`` lays them out."""

    def record(self, kind, body=b"", *, sequence=None, magic=records.MAGIC, version=records.VERSION):
        sequence = self.next_sequence() if sequence is None else sequence
        head = wire.pack(records.HEADER, {"magic": magic, "version": version, "type": kind,
                                          "sequence": sequence & 0xFF})
        return head + body

    def control(self, *, trigger=False, **config):
        names = [name for name, _ in records.MASTER_CONFIG]
        apply = sum(1 << names.index(name) for name in config)
        values = {name: 0 for name in names} | config
        body = wire.pack(records.MASTER_CONTROL, {"apply": apply, "action": int(Action.SOFTWARE_TRIGGER) * trigger,
                                                  **values})
        return self.record(RecordType.MASTER_CONTROL, body)

    async def records(self, encoded, *, port=None):
        await self.send([self.datagram(r, port=port) for r in encoded])

    async def status(self, **kwargs):
        return await super().status(RecordType.MASTER_STATUS, **kwargs)


async def start(dut, host, boards):
    """The master's clocks (all 125 MHz, a quarter nanosecond apart), its reset, every board
    ready; ``host`` listening on the transmit pins; returns the pulse monitor, running."""
    for name, value in (("gmii_rx", 0), ("trigger_in", 0), ("button", 0), ("ready", (1 << boards) - 1),
                        ("mdio_i", 1)):
        getattr(dut, name).value = value
    await start_clocks(dut, {"clk": NS, "gmii_rx_clk": NS, "gmii_tx_clk": NS})
    host.listen()
    pulses = Pulses(dut, boards)
    cocotb.start_soon(pulses.run())
    return pulses


@cocotb.test()
async def a_master_driven_over_gmii(dut):
    p = params()
    boards, clock_hz = p["boards"], p["clock_hz"]
    model = MasterModel(dmd=None, mac=address_value(p["mac"]), ip=address_value(p["ip"]), port=p["port"],
                        master=dict(p["config"]))
    host = Host(dut, p["mac"], p["ip"], p["port"], net=model)
    everyone = (1 << boards) - 1
    pulses = await start(dut, host, boards)
    counts = {"pulses": 0, "not_ready": 0, "early": 0}

    async def check_status():
        status = await host.status()
        for name, _ in records.NET_COUNTERS + records.MASTER_RECORD_COUNTERS:
            assert status[name] == model.counters[name], (name, status[name], model.counters[name])
        for name, value in model.master.items():
            assert status[name] == value, (name, status[name], value)
        for name, value in counts.items():
            assert status[name] == value, (name, status[name], value)
        assert (status["boards"], status["clock_hz"]) == (boards, clock_hz)
        assert status["mac_good"] == host.mac["good"] and status["mac_bad_fcs"] == 0
        return status

    async def pulse_expected(action, what):
        """``action`` (a coroutine) must give exactly one pulse of the configured width."""
        before = len(pulses.starts)
        await action
        await ClockCycles(dut.clk, 400)
        assert len(pulses.starts) == before + 1, f"{what}: {len(pulses.starts) - before} pulses, not 1"
        assert pulses.widths[-1] == model.master["width"], (what, pulses.widths[-1])
        counts["pulses"] += 1

    async def no_pulse(action, what):
        before = len(pulses.starts)
        await action
        await ClockCycles(dut.clk, 400)
        assert len(pulses.starts) == before, f"{what}: a pulse"

    async def raise_pin(signal):
        await FallingEdge(dut.clk)
        signal.value = 1
        await ClockCycles(dut.clk, 8)
        signal.value = 0

    # -- power-up: disarmed, EXTERNAL, the build's times ---------------------------------------------
    status = await check_status()
    assert status["ready"] == everyone and status["armed"] == 0
    await no_pulse(raise_pin(dut.trigger_in), "a pin trigger while disarmed")

    # -- software triggers by record; one too soon; a board not ready ------------------------------
    timing = {"min_period": 600, "width": 5}
    await pulse_expected(host.records([host.control(mode=TriggerMode.SOFTWARE, armed=1, trigger=True, **timing)]),
                         "a software trigger")
    await check_status()
    await pulse_expected(host.records([host.control(trigger=True), host.control(trigger=True)]),
                         "two triggers a record apart")
    counts["early"] += 1
    await ClockCycles(dut.clk, 600)
    dut.ready.value = everyone & ~(1 << (boards // 2))
    await no_pulse(host.records([host.control(trigger=True)]), "a trigger with a board not ready")
    counts["not_ready"] += 1
    dut.ready.value = everyone
    await check_status()

    # -- records the master drops: nothing applied, no trigger ---------------------------------------
    good = host.control(mode=TriggerMode.PERIODIC, period=800, trigger=True)
    bad = [
        host.record(RecordType.MASTER_CONTROL, good[5:], magic=0x4D44),
        host.record(RecordType.MASTER_CONTROL, good[5:], version=records.VERSION - 1),
        host.record(RecordType.CONTROL, good[5:]),
        host.record(RecordType.STATUS_REPLY),
        good + b"\0",                                   # one byte long
        good[:-1],                                      # one byte short
        host.record(RecordType.STATUS_QUERY, b"\0"),
        host.control(mode=TriggerMode.SYNC, trigger=True),
        host.control(mode=7, trigger=True),
        host.control(armed=2, trigger=True),
        host.control(width=0, trigger=True),
        host.control(width=600, trigger=True),          # a pulse as long as the shortest period
        host.control(min_period=5, trigger=True),       # shorter than the pulse
        host.control(mode=TriggerMode.PERIODIC, period=599, trigger=True),
    ]
    await ClockCycles(dut.clk, 600)
    await no_pulse(host.records(bad), "records the master drops")
    await no_pulse(host.records([host.control(trigger=True)], port=p["port"] + 1), "a record to another port")
    for cause in ("magic", "version", "type", "length", "value"):
        assert model.counters[f"drop_app_{cause}"] > 0, cause
    host.next_sequence(3)                               # a gap the master counts
    await pulse_expected(host.records([host.control(trigger=True)]), "a trigger after a gap")
    status = await check_status()
    assert status["sequence_gaps"] >= 1 and status["drop_udp_port"] == 1

    # -- the periodic mode: pulses a period apart ------------------------------------------------------
    period = 700
    first = len(pulses.starts)
    # (this one as the host library encodes it)
    await host.records([codec.master_control_record(host.next_sequence(), mode=TriggerMode.PERIODIC,
                                                    period=period)])
    await ClockCycles(dut.clk, 10 * period)
    await host.records([host.control(armed=0)])
    await ClockCycles(dut.clk, 2 * period)
    periodic = pulses.starts[first:]
    assert len(periodic) >= 8, periodic
    gaps = {b - a for a, b in zip(periodic, periodic[1:], strict=False)}
    assert gaps == {period}, f"periodic pulses {sorted(gaps)} cycles apart, not {period}"
    counts["pulses"] += len(periodic)
    assert all(width == model.master["width"] for width in pulses.widths[first:])
    await check_status()

    # -- the trigger pin, then the button (a software trigger) -----------------------------------------
    await host.records([host.control(mode=TriggerMode.EXTERNAL, armed=1)])
    await ClockCycles(dut.clk, 100)
    await pulse_expected(raise_pin(dut.trigger_in), "the trigger pin")
    await ClockCycles(dut.clk, 600)
    await no_pulse(raise_pin(dut.button), "the button in EXTERNAL mode")
    await host.records([host.control(mode=TriggerMode.SOFTWARE)])
    await ClockCycles(dut.clk, 100)
    await pulse_expected(raise_pin(dut.button), "the button in SOFTWARE mode")
    status = await check_status()
    assert model.triggers > 0 and status["pulses"] == len(pulses.starts)
