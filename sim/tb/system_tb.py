"""cocotb testbench of the projector's core (generated Verilog): configured, armed and fed over
GMII, triggered, the DLPC410 model on the pins, the camera's image compared with what was sent, and
the status reply read back from the GMII transmit pins. Run through :func:`sim.rigs.system_run.run`
by ``tests/test_system_verilog.py``.

Clocks: ``sync``, ``gmii_rx``, ``gmii_tx`` at 125 MHz and ``dmd`` at 200 MHz, started at
fractions of a nanosecond from each other so that no two domains' edges coincide. The MCB model
serves both memory ports; the DLPC410 model drives the controller's outputs and checks every
rule; every record is the host encoder's, inside a scapy-built UDP datagram. The core is built
disarmed with power-up registers unlike the run's: the run works only if its sequencer and
control records reach the sequencer.

The reference model of the network side (:class:`sim.models.net_model.Model`) sees every frame the
test sends and predicts the stack's and protocol's counters in the status reply; the test keeps
its own ledger of what the MAC, the sequencer and the store must have counted.

Faults during the run: frames with a bad FCS, frames for another UDP port and malformed records
(each class the parser drops) interleaved with the scene; a trigger while disarmed; a burst of
triggers faster than the frame rate; a new register set while a frame plays; a frame with a
lost record, then a whole one; the DDR2 losing its calibration while a frame plays (that frame
goes on dark, the next trigger shows dark, the next frame sent is shown). Every other frame shown
must be a whole, correct frame.
"""

import dataclasses
import json
import time
from pathlib import Path

import cocotb
import numpy as np
from cocotb.triggers import RisingEdge, Timer
from cocotb.utils import get_sim_time

from gateware.dlpc410.sequencer import Status as SequencerStatus
from gateware.store.slots import SlotCounters
from host import codec
from sim.harness.cocotb_run import params
from sim.harness.layout import unpack
from sim.models.camera_model import Camera, to_lsb
from sim.models.dlpc410_model import CocotbAdapter, Dlpc410
from sim.models.mcb_model import CocotbPort, McbModel
from sim.models.net_model import Model
from sim.rigs.scene import default_scene
from sim.rigs.system_run import plan as run_plan
from sim.tb.gmii_host import GmiiHost, address_value, start_clocks
from spec import records, wire
from spec.facts import DMDS
from spec.registers import PlaneOrder, TriggerMode

SYNC_NS, GMII_NS, DMD_NS = 8.0, 8.0, 5.0



def _now_ps():
    return round(get_sim_time("ps"))


class Edges:
    """The rising edges of a clock that cocotb's :class:`Clock` starts now (high first): counted
    from the simulation time, and waited for without waking the testbench on every one."""

    def __init__(self, clock, period_ns, *, first=None):
        self.clock, self.period = clock, round(period_ns * 1000)
        self.first = _now_ps() if first is None else first

    def count(self):
        """Rising edges so far, the one at this instant included."""
        now = _now_ps()
        return 0 if now < self.first else (now - self.first) // self.period + 1

    async def cycles(self, n):
        """As ``ClockCycles(clock, n)``: returns on the n-th rising edge from now. A timer runs
        to a quarter period after the edge before it (so the testbench waits for that last edge
        after the tasks that wait on every edge, as it would counting them), then the edge."""
        target = self.first + (self.count() + n - 1) * self.period
        wake = target - self.period + self.period // 4
        now = _now_ps()
        if wake > now:
            await Timer(wake - now, "ps")
        await RisingEdge(self.clock)
        assert _now_ps() == target, "the clock's edges are not where they were counted"


class System(GmiiHost):
    def __init__(self, dut, p):
        self.dut, self.p = dut, p
        self.dmd = DMDS[p["dmd"]]
        self.memory = McbModel(p["memory_bytes"], widths=CocotbPort.widths(dut, "mcb_write", "mcb_read"))
        self.plan = run_plan(p)
        self.dlpc = Dlpc410(self.dmd, clock_hz=1e9 / DMD_NS, rst_active_cycles=p["t_rst"],
                            settle_cycles=p["t_settle"], init_cycles=p["init_cycles"],
                            init_grace_cycles=p["init_grace"], check_training=p.get("check_training", True))
        super().__init__(dut, p["mac"], p["ip"], p["port"],
                         net=Model(self.dmd, address_value(p["mac"]), address_value(p["ip"]), p["port"]))
        self.dmd_clock = None            # the dmd clock's edges, once started

    @classmethod
    async def started(cls, dut):
        """The testbench's system on ``dut`` with the run's parameters, clocks and models running."""
        system = cls(dut, params())
        await system.start()
        return system

    async def start(self):
        dut = self.dut
        dut.gmii_rx.value = 0
        dut.trigger_in.value = 0
        dut.sync_in.value = 0
        dut.mdio_i.value = 1
        started = await start_clocks(dut, {"clk": SYNC_NS, "gmii_rx_clk": GMII_NS, "gmii_tx_clk": GMII_NS,
                                           "dmd_clk": DMD_NS})
        self.dmd_clock = Edges(dut.dmd_clk, DMD_NS, first=started["dmd_clk"])
        cocotb.start_soon(CocotbPort(dut, "mcb_write", dut.clk, self.memory.ports[0], SYNC_NS).run())
        cocotb.start_soon(CocotbPort(dut, "mcb_read", dut.dmd_clk, self.memory.ports[1], DMD_NS).run())
        # resting through quiet stretches: the testbench reads the model's commands, not its cycle
        self.adapter = cocotb.start_soon(CocotbAdapter(self.dlpc, dut, dut.dmd_clk, rest=True).run())
        self.listen()
        self.counted_from = self.dmd_clock.count()

    @property
    def dmd_cycle(self):
        """dmd cycles since the end of :meth:`start`: its rising edges, the one at this instant
        included (the count the DLPC410 model's cycles follow)."""
        return self.dmd_clock.count() - self.counted_from

    # -- what the host sends ----------------------------------------------------------------

    def image(self, picture, frame):
        encoded = codec.image_records(picture, frame, sequence=self.sequence)
        self.sequence += len(encoded)
        return encoded

    async def send(self, frames, bad_fcs=()):
        await super().send(frames, bad_fcs)
        self.sent_at = self.dmd_cycle

    async def delivered(self):
        """Wait until everything sent has taken effect: the projector handles datagrams in
        order, so when the answer to a status query sent after them is back, they have been
        handled; then ``settle_after_send`` cycles for the store to finish writing a frame and
        the sequencer to load it."""
        await self.status()
        await self.dmd_clock.cycles(self.p["settle_after_send"])

    async def deliver(self, frames, bad_fcs=()):
        await self.send(frames, bad_fcs)
        await self.delivered()

    async def records(self, encoded):
        """Send records, each in its own datagram to the projector, and wait until they have
        taken effect."""
        await self.deliver([self.datagram(r) for r in encoded])

    # -- triggers and what the DMD shows ---------------------------------------------------

    async def trigger(self):
        """A trigger edge on the pin; returns the dmd cycle it was raised on."""
        await RisingEdge(self.dut.dmd_clk)
        at = self.dmd_cycle
        self.dut.trigger_in.value = 1
        await self.dmd_clock.cycles(8)
        self.dut.trigger_in.value = 0
        return at

    def pulses_after(self, cycle):
        return [c for c in self.dlpc.log if c.kind == "pulse" and c.cycle >= cycle]


def bad_records(system, picture):
    """One malformed record of each class the parser checks, with the counter it lands in."""
    good_regs = records.register_wire(system.plan.params.registers(system.dmd))
    image = codec.image_records(picture[:1], 0, pixels=system.dmd.columns)[0]
    n, end = wire.size(records.HEADER), records.IMAGE_HEADER
    head = wire.unpack(records.HEADER, image)
    body = wire.unpack(records.IMAGE, image[n:])
    return [
        codec.sequencer_record({**good_regs, "lsb": good_regs["lsb"] + 1}, system.next_sequence()),
        codec.sequencer_record({**good_regs, "order": 4}, system.next_sequence()),    # order over 2 bits
        codec.sequencer_record(good_regs, system.next_sequence())[:-1],          # a byte short
        codec.control_record(system.next_sequence(), armed=2),
        codec.control_record(system.next_sequence(), bit_depth=9),
        wire.pack(records.HEADER, {**head, "version": records.VERSION + 1}) + image[n:],
        image[:n] + wire.pack(records.IMAGE, {**body, "offset": system.dmd.rows * system.dmd.columns}) + image[end:],
        wire.pack(records.HEADER, {**head, "type": records.RecordType.DELTA})          # a delta of no rows
        + wire.pack(records.DELTA, {**body, "base": 0, "carried": 0}) + image[end:],
    ]


@cocotb.test()
async def frames_over_gmii_are_shown_exactly(dut):
    system = await System.started(dut)
    p, dmd = system.p, system.dmd
    faults = p.get("faults", True)
    count = p["frames"] + (9 if faults else 0)
    if p.get("scene"):
        images = default_scene(count, dmd.rows, dmd.columns)
    else:
        rng = np.random.default_rng(p["seed"])
        images = [rng.integers(0, 256, (dmd.rows, dmd.columns), dtype=np.uint8) for _ in range(count)]
        images[0][0, :] = np.arange(dmd.columns) % 256      # every grey level appears
    if faults:
        # frames key + 1 .. key + 3: the key frame with a band of rows changed, sent as deltas
        key = p["frames"] + 5
        band_rng = np.random.default_rng(p["seed"] + 1)
        for j, first in enumerate((3, dmd.rows // 3, dmd.rows // 2)):
            images[key + 1 + j] = images[key].copy()
            images[key + 1 + j][first:first + 8] = band_rng.integers(0, 256, (8, dmd.columns), dtype=np.uint8)
    wall0 = time.monotonic()
    report = {"frames": [], "period_cycles": system.plan.frame_cycles, "rate_hz": system.plan.rate_hz,
              "lsb_cycles": system.plan.params.lsb}
    expect = {"triggers": 0, "trigger_overruns": 0, "registers_applied": 0, "frames_cut": 0}

    def encoded(index, *, interleave=True, lose=None):
        """Frame ``index``'s datagrams, with bad ones between them; ``lose``: a record left out."""
        payloads = system.image(images[index], frame=index)
        if lose is not None:
            del payloads[lose]
        frames = [system.datagram(r) for r in payloads]
        bad_fcs = ()
        if interleave:
            frames.insert(1, system.datagram(payloads[0], port=p["port"] + 1))   # another port
            frames.insert(2, system.datagram(payloads[1]))                         # its FCS broken
            bad_fcs = (2,)
            frames[3:3] = [system.datagram(r) for r in bad_records(system, images[index])]
        return frames, bad_fcs

    def delta(index, base):
        """Frame ``index`` as a delta of frame ``base``: the rows in which it differs from it."""
        rows = codec.changed_rows(images[index], images[base])
        payloads = codec.image_records(images[index], index, sequence=system.sequence, base=base, rows=rows)
        system.sequence += len(payloads)
        return [system.datagram(r) for r in payloads], ()

    async def show(index, plan, *, sending=None, burst=0, dark=False):
        """Trigger, and check that the camera sees frame ``index`` exactly under ``plan`` (or
        nothing: ``dark``); ``sending``: frames to send meanwhile; ``burst``: extra triggers
        while it plays."""
        period = plan.frame_cycles
        pin = await system.trigger()
        expect["triggers"] += 1
        task = cocotb.start_soon(system.send(*sending)) if sending else None
        for _ in range(burst):
            await system.dmd_clock.cycles(period // (burst + 1))
            await system.trigger()
            expect["trigger_overruns"] += 1
        await system.dmd_clock.cycles(period - burst * (period // (burst + 1)) + p["t_rst"] * 4)
        pulses = system.pulses_after(pin)
        if not pulses:     # the sequencer's counters, to say why
            counters = unpack(SequencerStatus, int(dut.sequencer.status.value))
            raise AssertionError(f"frame {index}: the trigger produced no clocking pulse; sequencer {counters}")
        first = pulses[0].cycle
        light = to_lsb(Camera(system.dlpc, ramp_cycles=0).image(first, first + period), plan.params.lsb)
        error = np.abs(light - (0 if dark else images[index].astype(np.float64)))
        report["frames"].append({"index": index, "latency_cycles": first - pin, "max_error_lsb": float(error.max()),
                                 "dark": dark})
        dut._log.info("frame %d: trigger to first pulse %d cycles, max error %.3g LSB", index, first - pin,
                      error.max())
        if error.max() >= 1e-9:     # what the store made of the rows, to say why
            matches = [j for j, other in enumerate(images) if np.abs(light - other).max() < 1e-9]
            dut._log.info("store counters %s", unpack(SlotCounters, int(dut.counters.value)))
            raise AssertionError(f"frame {index}: {int((error > 1e-9).sum())} pixels wrong; the image shown "
                                 f"equals sent frame(s) {matches}; period {period}, send ended at dmd cycle "
                                 f"{system.sent_at}, pulses {[(c.cycle, c.kind) for c in pulses[:3]]}")
        if task is not None:
            await task
            await system.delivered()

    # ---- configure through records, the first frame, a trigger while disarmed, then arm ----
    configure = [codec.sequencer_record(system.plan.params.registers(dmd), system.next_sequence(), dmd=dmd),
                 codec.control_record(system.next_sequence(), bit_depth=8, sequence_length=1)]
    await system.records(configure)
    expect["registers_applied"] += 1
    await system.deliver(*encoded(0))
    pin = await system.trigger()
    await system.dmd_clock.cycles(200)
    assert not system.pulses_after(pin), "a trigger reached the sequencer while disarmed"
    await system.records([codec.control_record(system.next_sequence(), armed=1)])

    # ---- streaming, as a renderer does it: each frame sent while the one before it is shown ----
    for index in range(p["frames"]):
        following = encoded(index + 1, interleave=faults) if index + 1 < count else None
        await show(index, system.plan, sending=following)

    if faults:
        n = p["frames"]
        # while a frame plays: a burst of triggers faster than the frame rate (overruns, the
        # frame shown whole), and a new register set (planes in the other order, twice as long)
        # with the next frame: the set is taken when the sequencer rests, and the next frame is
        # shown exactly under it
        later = run_plan(p, order=PlaneOrder.LSB_FIRST, exposure_s=2 * system.plan.params.lsb * DMD_NS * 1e-9)
        reconfigure = system.datagram(codec.sequencer_record(later.params.registers(dmd),
                                                               system.next_sequence(), dmd=dmd))
        frames, _ = encoded(n + 1, interleave=False)
        await show(n, system.plan, burst=3, sending=([reconfigure] + frames,))
        expect["registers_applied"] += 1
        await show(n + 1, later)
        # a frame with a lost record is never shown: the last whole frame repeats
        await system.deliver(*encoded(n + 2, interleave=False, lose=1))
        await show(n + 1, later)
        # ... until a newer whole frame comes
        await system.deliver(*encoded(n + 3, interleave=False))
        await show(n + 3, later)
        # the DDR2 loses its calibration a third into a frame and regains it 5 us later: the
        # frame goes on dark, and every frame is forgotten (the model raises on any word read
        # of the lost memory); the next trigger shows the frame held dark, and a frame sent
        # after the memory is back is shown exactly
        pin = await system.trigger()
        expect["triggers"] += 1
        expect["frames_cut"] += 1
        await system.dmd_clock.cycles(later.frame_cycles // 3)
        system.memory.lose_calibration(_now_ps() * 1e-12 + 100e-9, 5e-6)
        await system.dmd_clock.cycles(later.frame_cycles)
        assert system.memory.calib_losses == 1
        await show(n + 3, later, dark=True)
        await system.deliver(*encoded(n + 4, interleave=False))
        # (the triggers' pace is broken first: the frame is taken at once, not at the trigger after)
        await system.dmd_clock.cycles(later.frame_cycles)
        await show(n + 4, later)
        # delta frames: a whole key frame, two frames sent as only the rows in which they differ
        # from it (each shown exactly, the key kept for them), then a delta of frame n + 4, which
        # the store no longer holds: refused row by row, the frame before it shows again
        key = n + 5
        await system.deliver(*encoded(key, interleave=False))
        await show(key, later)
        for index in (key + 1, key + 2):
            await system.deliver(*delta(index, key))
            await show(index, later)
        await system.deliver(*delta(key + 3, n + 4))
        await show(key + 2, later)
        report["rows_no_base"] = len(codec.changed_rows(images[key + 3], images[n + 4]))

    # ---- the status reply: every counter as the test's ledger and the reference model say ----
    status = await system.status()
    report["status"] = status
    for name, _ in records.NET_COUNTERS + records.APP_COUNTERS:
        assert status[name] == system.net.counters[name], (name, status[name], system.net.counters[name])
    for verdict in ("good", "bad_fcs"):
        assert status[f"mac_{verdict}"] == system.mac[verdict], (verdict, status[f"mac_{verdict}"])
    shown = len(report["frames"]) + expect["frames_cut"]
    assert status["frames_shown"] == shown and status["triggers"] == expect["triggers"] == shown
    assert status["trigger_overruns"] == expect["trigger_overruns"]
    assert status["registers_applied"] == expect["registers_applied"] and status["registers_superseded"] == 0
    for name in ("triggers_early", "pulses_late", "frames_bad_depth", "mac_rx_er",
                 "mac_runt", "mac_oversize", "mac_preamble", "mac_rx_dropped", "mac_tx_underruns"):
        assert status[name] == 0, (name, status[name])
    assert status["store_frames_abandoned"] == (1 if faults else 0)
    # (with the faults: the frame with a lost record, and the delta without its base)
    assert status["store_frames_complete"] == count - (2 if faults else 0)
    assert status["store_rows_no_base"] == report.get("rows_no_base", 0)
    # the loss: the frame held, the one it was about to take (the same) ... every slot in use
    assert status["store_calibration_losses"] == (1 if faults else 0)
    assert status["store_frames_lost"] == (1 if faults else 0), status["store_frames_lost"]
    assert status["dlpc410_state"] & 0b1001 == 0b1000, "DLPC410 initialised and memory calibrated"
    assert status["clock_hz"] == 125_000_000
    report["wall_s"] = time.monotonic() - wall0
    report["dmd_cycles"] = system.dmd_cycle
    report["gmii_frames_sent"] = system.frames_sent
    report["dlpc410_commands"] = len(system.dlpc.log)
    Path(p["report"]).write_text(json.dumps(report))


@cocotb.test()
async def sequence_entries_play_as_their_table_says(dut):
    """A stored sequence of seven 8-bit frames (56 bit-planes, more than a DLPC350's 48) played
    by an entry table of three of them, once, configured over GMII as a host does it (sequence
    mode, the entry records, the control record that plays them, then the frames): one trigger
    shows the three entries back to back (one at twice the exposure and without a camera
    trigger, one at 4 bits below its frame's two most significant: bits 2..5; the last two
    following with no trigger), every pixel's light is each entry's frame at its own exposure
    and planes, and a trigger after the last entry is ignored and counted."""
    system = await System.started(dut)
    p, dmd, plan = system.p, system.dmd, system.plan
    rng = np.random.default_rng(p["seed"] + 7)
    images = [rng.integers(0, 256, (dmd.rows, dmd.columns), dtype=np.uint8) for _ in range(7)]
    lsb = plan.params.lsb
    # (slot, lsb, follow, camera, depth, skip): entry 0 waits for the trigger, the others follow
    table = [(6, 0, False, True, 0, 0), (0, 2 * lsb, True, False, 0, 0), (3, 0, True, True, 4, 2)]
    await system.records([codec.sequencer_record(plan.params.registers(dmd), system.next_sequence(), dmd=dmd),
                          codec.control_record(system.next_sequence(), bit_depth=8, sequence_length=len(images),
                                               armed=1)])
    entries = [codec.entry_record(k, slot, system.next_sequence(), lsb=entry_lsb, follow=follow, camera=camera,
                                  depth=depth, skip=skip)
               for k, (slot, entry_lsb, follow, camera, depth, skip) in enumerate(table)]
    await system.records([*entries, codec.control_record(system.next_sequence(), entries=len(table), loop=0,
                                                         sequence_start=True)])
    for slot, image in enumerate(images):
        await system.deliver([system.datagram(r) for r in system.image(image, frame=slot)])
    # the sequence's first entry is loaded once the store holds both frames: then one trigger
    await system.dmd_clock.cycles(2 * plan.frame_cycles)
    pin = await system.trigger()
    span = sum((entry_lsb or lsb) * (2 ** (depth or 8) - 1) for _, entry_lsb, _, _, depth, _ in table) \
        + len(table) * plan.frame_cycles
    await system.dmd_clock.cycles(span)
    pulses = system.pulses_after(pin)
    assert pulses, "the trigger produced no clocking pulse"
    late = await system.trigger()
    await system.dmd_clock.cycles(plan.frame_cycles)
    assert not system.pulses_after(late), "a trigger after a sequence played once showed a frame"
    light = Camera(system.dlpc, ramp_cycles=0).image(pulses[0].cycle, late)
    # an entry at d bits below s left out shows bits 8 - d - s .. 7 - s of its frame's values
    expect = sum(((images[slot].astype(np.int64) >> (8 - (depth or 8) - skip)) & ((1 << (depth or 8)) - 1))
                 * (entry_lsb or lsb) for slot, entry_lsb, _, _, depth, skip in table)
    assert np.array_equal(light, expect), f"max error {np.abs(light - expect).max() / lsb:.3g} LSB"
    status = await system.status()
    assert status["records_entry"] == len(table) and status["drop_app_value"] == 0, status
    assert status["frames_shown"] == len(table) and status["triggers"] == 1, status
    assert status["triggers_after_end"] == 1 and status["store_frames_complete"] == len(images), status
    assert status["sequence_entries_skipped"] == 0 and status["pulses_late"] == 0, status
    Path(p["report"]).write_text(json.dumps({"latency_cycles": pulses[0].cycle - pin, "status": status}))


#: The sync master's period in the tiled board's test, in ``dmd`` cycles (beyond the clock loop's
#: capture range, so that a pulse left out is a slip).
TILED_PERIOD = 2000


@cocotb.test()
async def a_tiled_board_trims_its_clock(dut):
    """A board of a tiled display, configured over GMII as a host does it: SYNC trigger mode with
    the master's period. The sync pulses come every period on ``sync_in``: the clock loop runs
    (``vcxo_trim`` leaves 0; the simulation's clock is exact and cannot be pulled, so the loop
    never locks); a pulse left out is a slip in the status reply; back in trigger-pin mode the
    loop is off and the trim word 0 again."""
    system = await System.started(dut)
    dmd, plan = system.dmd, system.plan
    sync = dataclasses.replace(plan.params, trigger=TriggerMode.SYNC, period=TILED_PERIOD)
    await system.records([codec.sequencer_record(sync.registers(dmd), system.next_sequence(), dmd=dmd),
                          codec.control_record(system.next_sequence(), armed=1)])
    trims = []
    for k in range(12):
        if k != 8:                                  # the ninth pulse left out: a slip
            dut.sync_in.value = 1
        await system.dmd_clock.cycles(4)
        dut.sync_in.value = 0
        await system.dmd_clock.cycles(TILED_PERIOD - 4)
        trims.append(dut.vcxo_trim.value.to_signed())
    status = await system.status()
    assert status["drop_app_value"] == 0 and status["registers_applied"] >= 1, status
    assert status["clock_loop_slips"] == 1 and status["clock_loop_locked"] == 0, status
    assert all(t != 0 for t in trims[1:]), trims       # the first pulse only anchors the loop
    # the trigger pin's mode, the period left set: the mode turns the loop off
    pin = dataclasses.replace(plan.params, period=TILED_PERIOD)
    await system.records([codec.sequencer_record(pin.registers(dmd), system.next_sequence(), dmd=dmd)])
    await system.dmd_clock.cycles(8)
    assert dut.vcxo_trim.value.to_signed() == 0, "the loop is off outside SYNC mode"
    Path(system.p["report"]).write_text(json.dumps({"trims": trims, "status": status}))
