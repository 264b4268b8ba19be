"""The system simulation's fast top: the projector's core with its surroundings in Verilog.

Simulation only. Around :class:`gateware.top.system.Projector` it places the Verilog models of
``sim/hdl/`` so that nothing in Python runs per cycle:

* ``gmii_replay.v`` plays a GMII receive file written by :mod:`sim.models.gmii_stim` (the host
  encoder's records in scapy-built datagrams) into ``gmii_rx``;
* ``mcb_model.v`` is the memory behind both MCB ports, with the timing of
  :class:`sim.models.mcb_model.McbTiming` (bandwidth shared by the ports, refresh);
* ``dlpc410_responder.v`` drives INIT_ACTIVE, RST_ACTIVE and ECP2_FINISHED as the DLPC410 model
  does (the offline replay cross-checks them);
* two ``trace_recorder.v`` write the DLPC410 pins (with the trigger, sync and camera pins) and the
  GMII transmit pins to files, only on cycles where something happens, for the rule-checking
  model and the camera model (:mod:`sim.models.trace`) after the run;
* with ``window``, ``wave_window.v`` dumps every signal of the design while ``wave_dump`` is high
  (a build with tracing: :data:`WINDOW_SOURCES`).

Clocks come from the testbench: ``clk`` (125 MHz) and ``dmd_clk`` (200 MHz); resets are made
inside. The GMII receive and transmit domains run on ``clk`` here: every edge costs the simulator
an evaluation, and three 125 MHz clocks apart would cost three (the small-geometry run,
:mod:`sim.tb.system_tb`, keeps all four clocks apart). The trigger comes from the testbench too.
"""

import math

from amaranth import Cat, ClockDomain, ClockSignal, Const, Instance, Module, ResetSignal, Shape, Signal, Value
from amaranth.lib import data, wiring
from amaranth.lib.wiring import In, Out

from gateware.mac import gmii
from gateware.store import mcb
from gateware.top.system import Projector
from sim.harness.paths import ROOT
from sim.models.dlpc410_model import timing_cycles
from sim.models.dlpc410_replay import Replay
from sim.models.mcb_model import McbTiming

__all__ = ["FastSystem", "ResponderBench", "dlpc410_side", "power_on_reset", "pin_layout", "SOURCES", "PLUSARGS",
           "WINDOW_SOURCES", "read_rate", "INGEST_BYTES_PER_S"]

#: The Verilog models the top instantiates.
SOURCES = [ROOT / "sim" / "hdl" / name for name in
           ("gmii_replay.v", "mcb_model.v", "dlpc410_responder.v", "trace_recorder.v")]
#: The wave window's model and its DPI function (a Verilator build with tracing).
WINDOW_SOURCES = [ROOT / "sim" / "hdl" / name for name in ("wave_window.v", "wave_window.cpp")]
#: Plusargs naming the files: GMII replay in, DLPC410 pin trace, GMII transmit trace and the
#: wave window's dump out.
PLUSARGS = {"replay": "GMII_REPLAY", "pins": "DLPC_TRACE", "tx": "GMII_TX_TRACE", "window": "WAVE_WINDOW"}

#: ECP2_FINISHED rises on this cycle (the DLPC410 model's default).
ECP2_CYCLES = 4

#: Cycles each domain stays in reset after its clock starts.
RESET_CYCLES = 4

#: GMII line rate in bytes per second: the store's write traffic at most (a pixel byte makes a
#: byte of bit-planes).
INGEST_BYTES_PER_S = 125e6


def pin_layout(buses, beats=1):
    """One record of the DLPC410 pin trace: the pins the model reads (data and DVALID on every
    DCLK edge of the cycle), the controller's outputs the responder drove, and the trigger, sync,
    camera and light gate pins."""
    return data.StructLayout({
        **{f"din_{b}": 32 * beats for b in "abcd"[:buses]},
        "dvalid": 2 * beats, "rowmd": 2, "rowad": 11, "blkmd": 2, "blkad": 4, "rst2blkz": 1, "comp_data": 1,
        "ns_flip": 1, "wdt_enblz": 1, "pwr_float": 1, "arstz": 1,
        "init_active": 1, "rst_active": 1, "ecp2_finished": 1,
        "trigger_in": 1, "sync_out": 1, "camera_out": 1, "gate_out": 1,
    })


def read_rate(timing, dmd_hz, ingest_bytes_per_s=INGEST_BYTES_PER_S):
    """64-bit words per ``dmd`` cycle the plane reader can count on: the DDR2's sustained
    bandwidth (refresh taken off) less the store's writes at the GMII line rate. The memory
    model gives the reader this much under that ingest (``store.read_words_per_dmd_cycle_with_
    ingest``, :mod:`sim.bench.store_figures`; a test holds the two together). On the Atlys (DDR2-800 x16,
    1.6 GB/s peak) it is under one word a cycle at 200 MHz whatever the port's width.
    ``ingest_bytes_per_s``: the store's writes; frames of fewer planes write less (a pixel byte
    of a 1-bit frame makes one bit)."""
    return (timing.sustained_bytes_per_s - ingest_bytes_per_s) / 8 / dmd_hz


def dlpc410_side(m, dmd, dlpc, *, rst_active_cycles, init_cycles, init_grace_cycles, flush,
                 ecp2_cycles=ECP2_CYCLES, restart_at=0, restart_cycles=0, restart_ecp2_cycles=0,
                 extra=None, layout=None, always=None, domain="dmd", plusarg=PLUSARGS["pins"]):
    """The DLPC410's side of the pins ``dlpc`` (an interface of
    :class:`gateware.dlpc410.interface.Signature`, seen from its driver): the responder drives the
    controller's outputs (its cycle counts: ints, or signals set at run time; ``restart_*``: a
    restart mid-run, none when ``restart_cycles`` is 0), the recorder writes
    the pins and ``extra`` (``{field: signal}`` of ``layout``'s other fields; default layout
    :func:`pin_layout`) to the file of plusarg ``plusarg`` (one per board where several share a
    simulation), on every cycle with DVALID or ``always`` high and every cycle something
    changed. The interface's ``beats`` (DCLK cycles
    per cycle) set the row cycle's length in cycles and the trace's widths."""
    beats = dlpc.signature.beats
    rst_active, init_active, ecp2 = Signal(), Signal(), Signal()
    timing = {name: Value.cast(Const(value, 32) if isinstance(value, int) else value)
              for name, value in (("rst_active_cycles", rst_active_cycles), ("init_cycles", init_cycles),
                                  ("init_grace_cycles", init_grace_cycles), ("ecp2_cycles", ecp2_cycles),
                                  ("restart_at", restart_at), ("restart_cycles", restart_cycles),
                                  ("restart_ecp2_cycles", restart_ecp2_cycles))}
    m.submodules.responder = Instance(
        "dlpc410_responder",
        p_CYCLES_PER_ROW=dmd.dclk_per_row // beats, **{f"i_{name}": value for name, value in timing.items()},
        i_clk=ClockSignal(domain), i_rst=ResetSignal(domain), i_arstz=dlpc.arstz, i_dvalid=dlpc.dvalid[0],
        i_blkmd=dlpc.blkmd,
        o_init_active=init_active, o_rst_active=rst_active, o_ecp2_finished=ecp2)
    m.d.comb += [dlpc.rst_active.eq(rst_active), dlpc.init_active.eq(init_active),
                 dlpc.ecp2_finished.eq(ecp2), dlpc.dmd_type.eq(dmd.dmd_type_code or 0)]
    layout = pin_layout(dmd.buses, beats) if layout is None else layout
    pins = Signal(layout)
    for name, _ in layout:
        if hasattr(dlpc, name):
            m.d.comb += getattr(pins, name).eq(getattr(dlpc, name))
    for name, signal in (extra or {}).items():
        m.d.comb += getattr(pins, name).eq(signal)
    m.submodules.pin_trace = Instance(
        "trace_recorder", p_WIDTH=len(pins.as_value()), p_PLUSARG=plusarg,
        i_clk=ClockSignal(domain), i_rst=ResetSignal(domain), i_value=pins.as_value(),
        i_always_record=dlpc.dvalid.any() if always is None else dlpc.dvalid.any() | always, i_flush=flush)


def power_on_reset(m, domain, clock):
    """Domain ``domain`` on ``clock``, held in reset for its first ``RESET_CYCLES`` cycles by a
    counter. A reset port would make Verilator re-evaluate, on every clock edge, all the logic
    that depends on it (that is, nearly all): an internal reset is evaluated with its
    registers."""
    m.domains += [ClockDomain(domain), ClockDomain(f"{domain}_por", reset_less=True)]
    m.d.comb += [ClockSignal(domain).eq(clock), ClockSignal(f"{domain}_por").eq(clock)]
    count = Signal(range(RESET_CYCLES + 1), name=f"{domain}_por_count")
    with m.If(count != RESET_CYCLES):
        m.d[f"{domain}_por"] += count.eq(count + 1)
    m.d.comb += ResetSignal(domain).eq(count != RESET_CYCLES)


class ResponderBench(wiring.Component):
    """:func:`dlpc410_side` behind :class:`sim.models.dlpc410_replay.Replay`: the responder and the
    pin recorder on driver-built cycle sequences, in ``sync``.

    Members
    -------
    select : In; done : Out(1)
        As :class:`~sim.models.dlpc410_replay.Replay`'s.
    flush : In(1)
        Writes the recorder's buffered lines to its file.
    """

    def __init__(self, dmd, sequences, *, rst_active_cycles, init_cycles, init_grace_cycles=0):
        self._replay = Replay(dmd, sequences)
        self._dmd = dmd
        self._timing = dict(rst_active_cycles=rst_active_cycles, init_cycles=init_cycles,
                            init_grace_cycles=init_grace_cycles)
        super().__init__({"select": In(len(self._replay.select)), "done": Out(1), "flush": In(1)})

    def elaborate(self, platform):
        m = Module()
        m.submodules.replay = replay = self._replay
        m.d.comb += [replay.select.eq(self.select), self.done.eq(replay.done)]
        dlpc410_side(m, self._dmd, replay.dlpc, flush=self.flush, domain="sync", **self._timing)
        return m


class FastSystem(wiring.Component):
    """The projector's core with GMII replay, memory, DLPC410 responder and pin recorders.

    Parameters
    ----------
    dmd : DmdType
    registers : dict
        The sequencer's registers (:class:`gateware.registers.Registers` fields), fixed for
        the run.
    mac, ip, port : int
        The core's addresses.
    clocks : dict
        ``{"sync": Hz, "dmd": Hz}`` (the memory timing is converted to each port's cycles).
    init_cycles, init_grace_cycles : int
        The responder's initialisation time and grace (as the DLPC410 model's).
    memory_words : int
        64-bit words of memory.
    timing : McbTiming, optional
        DDR2 timing (default :class:`sim.models.mcb_model.McbTiming`, the Python model's).
    beats : int
        DCLK cycles per ``dmd`` cycle (2: DCLK 400 MHz).
    window : bool
        Adds the wave window (``wave_dump``, ``sync_out``); build with :data:`WINDOW_SOURCES`
        and tracing.

    Members
    -------
    clk, dmd_clk : In(1)
        125 MHz (``sync`` and both GMII domains) and 200 MHz (``dmd``); each domain leaves reset
        ``RESET_CYCLES`` cycles after its clock starts.
    trigger_in : In(1)
        The trigger pin.
    replay_start : In(1); replay_busy : Out(1)
        A pulse plays the GMII replay file (the file is opened at the pulse); busy while playing.
    flush : In(1)
        Writes the recorders' buffered lines to their files.
    mcb_fault : Out(8)
        The memory ports' rule-break codes (``mcb_model.v``), 4 bits per port; 0 = none.
    mcb_stalls : Out(32)
        Commands the memory model stalled at random (plusargs; none by default).
    wave_dump : In(1); sync_out : Out(1); loading : Out(1)
        With ``window``: every signal is dumped while ``wave_dump`` is high (once, to the file
        of plusarg ``PLUSARGS["window"]``); the core's sync out, for the testbench to close the
        window after a frame's first pulse; DVALID (a row on the bus), for it to trigger once
        the first frame is being loaded (a trigger before the sequencer runs is ignored).
    """

    def __init__(self, dmd, registers, *, mac, ip, port, clocks, init_cycles=200, init_grace_cycles=4,
                 memory_words=1 << 21, timing=None, beats=1, window=False):
        self._dmd, self._beats = dmd, beats
        self._registers = registers
        self._addresses = dict(mac=mac, ip=ip, port=port)
        self._clocks = clocks
        self._init = (init_cycles, init_grace_cycles)
        self._memory_words = memory_words
        self._timing = timing or McbTiming()
        self._window = window
        super().__init__({
            "clk": In(1),
            "dmd_clk": In(1),
            "trigger_in": In(1),
            "replay_start": In(1),
            "replay_busy": Out(1),
            "flush": In(1),
            "mcb_fault": Out(8),
            "mcb_stalls": Out(32),
            **({"wave_dump": In(1), "sync_out": Out(1), "loading": Out(1)} if window else {}),
        })

    def _memory(self, m, core):
        t = self._timing
        hz = [self._clocks["sync"], self._clocks["dmd"]]

        def cycles(seconds):
            return Const(sum(max(1, math.ceil(seconds * f)) << (32 * i) for i, f in enumerate(hz)), 64)

        ports = [core.mcb_write, core.mcb_read]
        connections = {}
        # the model gives each port the slots of the widest one: pad the narrower ports' members
        for name, member in mcb.PortSignature(max(mcb.WIDTHS)).members.items():
            slot = Shape.cast(member.shape).width
            parts = []
            for p in ports:
                value = getattr(p, name)
                pad = slot - len(Value.cast(value))
                parts += [value, *([Signal(pad, name=f"{name}_pad")] if pad else [])]
            # Out members are driven by the core: inputs of the model
            connections[("i_" if member.flow == wiring.Out else "o_") + name] = Cat(*parts)
        m.submodules.memory = Instance(
            "mcb_model",
            p_PORTS=2, p_WORDS=self._memory_words,
            p_WIDTH=Const(sum(p.signature.width << (32 * i) for i, p in enumerate(ports)), 64),
            p_CALIB_CYCLES=cycles(t.calib_delay_s), p_CMD_LATENCY=cycles(t.command_latency_s),
            p_WORD_NS=t.word_s * 1e9, p_READ_LATENCY_NS=t.read_latency_s * 1e9,
            p_REFRESH_INTERVAL_NS=t.refresh_interval_s * 1e9, p_REFRESH_NS=t.refresh_s * 1e9,
            i_clk=Cat(ClockSignal("sync"), ClockSignal("dmd")),
            o_fault=self.mcb_fault, o_stalls=self.mcb_stalls,
            # unread, but Verilator warns of an output left out of the instance (PINMISSING)
            o_calib_losses=Signal(32, name="mcb_calib_losses"),
            **connections)

    def _clocks_and_resets(self, m):
        """Domains from the two clock ports; resets from a counter in each (:func:`power_on_reset`);
        the GMII domains on ``clk`` share ``sync``'s reset."""
        power_on_reset(m, "sync", self.clk)
        power_on_reset(m, "dmd", self.dmd_clk)
        for name in ("gmii_rx", "gmii_tx"):
            m.domains += ClockDomain(name)
            m.d.comb += [ClockSignal(name).eq(self.clk), ResetSignal(name).eq(ResetSignal("sync"))]

    def elaborate(self, platform):
        m = Module()
        dmd = self._dmd
        self._clocks_and_resets(m)
        # The sequencer's registers for the run are the core's power-up registers.
        m.submodules.core = core = Projector(dmd, **self._addresses, regs=self._registers,
                                             sync_hz=self._clocks["sync"], mdio_cycles=(40, 10), beats=self._beats)
        m.d.comb += [core.trigger_in.eq(self.trigger_in), core.sync_in.eq(0), core.mdio_i.eq(1)]

        rx = Signal(gmii.RxPins)
        m.submodules.replay = Instance(
            "gmii_replay",
            i_clk=ClockSignal("gmii_rx"), i_start=self.replay_start,
            o_rx_d=rx.d, o_rx_dv=rx.dv, o_rx_er=rx.er, o_busy=self.replay_busy)
        m.d.comb += core.gmii_rx.eq(rx)

        self._memory(m, core)

        cycles = timing_cycles(self._clocks["dmd"])
        dlpc410_side(m, dmd, core.dlpc, rst_active_cycles=cycles["rst_active_cycles"], init_cycles=self._init[0],
                     init_grace_cycles=self._init[1], flush=self.flush,
                     extra={"trigger_in": self.trigger_in, "sync_out": core.sync_out,
                            "camera_out": core.camera_out, "gate_out": core.gate_out})
        tx = Signal(gmii.TxPins)
        m.d.comb += tx.eq(core.gmii_tx)
        m.submodules.tx_trace = Instance(
            "trace_recorder", p_WIDTH=len(tx.as_value()), p_PLUSARG=PLUSARGS["tx"],
            i_clk=ClockSignal("gmii_tx"), i_rst=ResetSignal("gmii_tx"), i_value=tx.as_value(), i_always_record=tx.en,
            i_flush=self.flush)
        if self._window:
            m.submodules.wave_window = Instance("wave_window", i_dump=self.wave_dump)
            m.d.comb += [self.sync_out.eq(core.sync_out), self.loading.eq(core.dlpc.dvalid.any())]
        return m
