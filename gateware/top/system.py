"""The projector's core: every block from the GMII pins to the DLPC410 pins, no vendor primitive.

Layers, as data flows through them (one banner each below):

* Ethernet (:class:`gateware.protocol.port.EthernetPort`): the MAC in ``gmii_rx`` / ``gmii_tx``, its
  FIFOs into ``sync``, the network stack and the application protocol;
* bit-plane serialiser and the store's writer (``sync``), DDR2 through MCB port 0;
* the store's slots and plane reader (``dmd``), MCB port 1;
* the frame broker and the DLPC410 sequencer (``dmd``), its register sets crossing from the
  protocol (:class:`.control.RegisterCrossing`) and the arming of its triggers;
* status: counters of every domain carried into ``sync`` for the status reply.

The top that instantiates this defines the four clock domains and connects the MCB ports to the
memory controller (platform) or the MCB model (simulation).
"""

from amaranth import Cat, DomainRenamer, Module, Mux, Signal, signed
from amaranth.lib import data, wiring
from amaranth.lib.cdc import FFSynchronizer, PulseSynchronizer
from amaranth.lib.wiring import In, Out

from gateware.bitplane import Serialiser
from gateware.cdc import CountSynchronizer
from gateware.dlpc410 import interface
from gateware.dlpc410.register_crossing import RegisterCrossing
from gateware.dlpc410.sequencer import Sequencer
from gateware.mac import gmii
from gateware.mac.mdio import StatusPoller
from gateware.protocol.endpoint import Endpoint
from gateware.protocol.port import EthernetPort, report_port
from gateware.queue import AsyncQueue, Queue
from gateware.registers import LSB_BITS, TriggerMode
from gateware.store import mcb
from gateware.store.broker import FrameBroker
from gateware.store.layouts import SLOT_BITS, FrameInfo
from gateware.store.store import Store
from gateware.sync.clock_trim import TRIM_BITS, ClockTrim
from spec.records import sequence_frames

__all__ = ["Projector", "ShownFrame", "slots_for"]


def slots_for(dmd):
    """Frame slots the projector keeps in DDR2: every whole frame the Atlys's 128 MiB hold, up to
    what the slot numbers name (``SLOT_BITS``): 170 XGA frames (1,360 bit-planes), 60 DLP9500
    ones. A stored sequence holds up to this many frames; streaming and delta frames use the
    first :data:`~gateware.store.layouts.LIVE_SLOTS`."""
    assert sequence_frames(dmd.rows, dmd.columns) <= 2**SLOT_BITS
    return sequence_frames(dmd.rows, dmd.columns)


FRAME_BITS = 16


class ShownFrame(data.Struct):
    """The frame the DMD shows, from its first clocking pulse: how many frames have started
    (wrapping: it steps at each, a repeat included), the frame's id, its bit depth and the
    duration of its least significant plane (``dmd`` cycles), so that whoever watches the mirrors
    knows the frame and its full-scale light (``lsb * (2**depth - 1)``)."""
    number: 8
    frame: FRAME_BITS
    depth: 4
    lsb: LSB_BITS


class Projector(wiring.Component):
    """The simulated core of the projector.

    Parameters
    ----------
    dmd : DmdType
    mac, ip, port : int
        Network addresses at reset.
    regs : dict or :class:`amaranth.lib.data.Const` of :class:`gateware.registers.Registers`
        The sequencer's registers at reset (for example a :func:`spec.schedule.plan`'s
        ``params.registers(dmd)``); sequencer records replace them at run time.
    armed : bool
        Whether triggers reach the sequencer at reset; control records arm and disarm.
    sync_hz : float
        ``sync`` frequency (status replies report it; the PHY management derives MDC from it).
    slots : int
        Frame slots in DDR2 (default :func:`slots_for`): a stored sequence holds up to this many
        frames.
    beats : int
        DCLK cycles per ``dmd`` cycle: 2 for DCLK 400 MHz (the platform's 4:1 serialisers), 1
        for 200 MHz.
    mdio_cycles : tuple(int, int), optional
        PHY reset and settle waits in ``sync`` cycles (simulations shorten them).
    sync_pad_sampled : bool
        The board samples the sync input on both edges in its pad: the clock loop takes the
        falling half (``sync_in_fall``); otherwise it samples ``sync_in`` itself.

    Members
    -------
    gmii_rx : In(gmii.RxPins)
        PHY receive pins (``gmii_rx``).
    gmii_tx : Out(gmii.TxPins)
        PHY transmit pins (``gmii_tx``).
    phy_reset_n, mdc, mdio_o, mdio_oe : Out(1); mdio_i : In(1)
        PHY reset and management (``sync``).
    mcb_write : Out(mcb.PortSignature(64))
        MCB port 0 (``sync``), the store's writer.
    mcb_read : Out(mcb.PortSignature(128))
        MCB port 1 (``dmd``), the store's plane reader.
    dlpc : Out(dlpc410.interface.Signature)
        The DLPC410 applications interface (``dmd``).
    trigger_in, sync_in : In(1)
        TTL trigger and sync inputs (asynchronous).
    sync_in_fall : In(1)
        With ``sync_pad_sampled`` only: the sync input's sample on the falling edge of ``dmd``,
        taken in the pad (the falling half of the DDR input register whose rising half is
        ``sync_in``), for the clock loop's phase detector.
    sync_out, camera_out : Out(1)
        Frame shown; camera trigger (``dmd``).
    gate_out : Out(1)
        The light gate (``dmd``): switches a modulated light source during gated planes
        (:class:`gateware.dlpc410.light_gate.LightGate`); high while no plane is gated.
    ready_out : Out(1)
        A trigger or sync pulse now would be obeyed at once (``dmd``): the ready line to a tiled
        display's sync master.
    shown : Out(ShownFrame)
        The frame shown last (``dmd``); its id also reaches the status reply (``shown_frame``).
    vcxo_trim : Out(signed(16))
        The control word of the ``dmd`` clock's VCXO (``dmd``), for a board of a tiled display:
        in SYNC trigger mode with a non-zero ``period`` (the sync period in ``dmd`` cycles), the
        clock loop (:class:`gateware.sync.clock_trim.ClockTrim`) pulls the clock to the sync
        master's rate; else 0. A board without a VCXO leaves it unconnected.
    """

    def __init__(self, dmd, *, mac, ip, port, regs, armed=True, sync_hz=125e6, slots=None, mdio_cycles=None,
                 beats=1, sync_pad_sampled=False):
        self._dmd = dmd
        self._addresses = dict(mac=mac, ip=ip, port=port)
        self._regs = regs
        self._armed = armed
        self._sync_hz = sync_hz
        self._slots = slots_for(dmd) if slots is None else slots
        self._mdio_cycles = mdio_cycles or (None, None)
        self._beats = beats
        self._sync_pad_sampled = sync_pad_sampled
        super().__init__({
            "gmii_rx": In(gmii.RxPins),
            "gmii_tx": Out(gmii.TxPins),
            "phy_reset_n": Out(1),
            "mdc": Out(1),
            "mdio_o": Out(1),
            "mdio_oe": Out(1),
            "mdio_i": In(1),
            "mcb_write": Out(mcb.PortSignature(64)),
            "mcb_read": Out(mcb.PortSignature(128)),
            "dlpc": Out(interface.Signature(dmd.buses, beats)),
            "trigger_in": In(1),
            "sync_in": In(1),
            **({"sync_in_fall": In(1)} if sync_pad_sampled else {}),
            "sync_out": Out(1),
            "camera_out": Out(1),
            "gate_out": Out(1),
            "ready_out": Out(1),
            "shown": Out(ShownFrame),
            "vcxo_trim": Out(signed(TRIM_BITS)),
        })

    def elaborate(self, platform):
        m = Module()
        dmd = self._dmd

        # ---- Ethernet: GMII MAC, stack and application protocol (gmii_rx / gmii_tx -> sync) ------
        m.submodules.ethernet = ethernet = EthernetPort(Endpoint(dmd, frame_bits=FRAME_BITS, armed=self._armed,
                                                                 beats=self._beats, **self._addresses))
        m.d.comb += [ethernet.gmii_rx.eq(self.gmii_rx), self.gmii_tx.eq(ethernet.gmii_tx)]

        m.submodules.phy = phy = StatusPoller(self._sync_hz, reset_cycles=self._mdio_cycles[0],
                                              settle_cycles=self._mdio_cycles[1])
        m.d.comb += [
            self.phy_reset_n.eq(phy.phy_reset_n), self.mdc.eq(phy.mdc),
            self.mdio_o.eq(phy.mdio_o), self.mdio_oe.eq(phy.mdio_oe), phy.mdio_i.eq(self.mdio_i),
        ]

        # ---- Bit-plane serialiser and the store (sync, then dmd) -------------------------------
        m.submodules.serialiser = serialiser = Serialiser(dmd, lanes=1, frame_bits=FRAME_BITS)
        wiring.connect(m, ethernet.pixels, serialiser.pixels)
        # The reader reads 128-bit port words (two plane words); a sequencer that takes one word a
        # cycle (two buses, one DCLK beat a cycle) gets them one at a time.
        store_words = min(2, dmd.bits_per_dclk * self._beats // 64)
        m.submodules.store = store = Store(dmd, slots=self._slots, frame_bits=FRAME_BITS, read_width=128,
                                           plane_words=store_words)
        # a queue on each of the serialiser's streams: the store's ready (its writer asks whether
        # a word joins its open bank) ends at the queue, and the serialiser and the endpoint
        # behind it see the queue's own, from its level
        for name in ("words", "rows"):
            source = getattr(serialiser, name)
            m.submodules[f"to_store_{name}"] = queue = Queue(source.payload.shape(), depth=2)
            wiring.connect(m, source, queue.w_stream)
            wiring.connect(m, queue.r_stream, getattr(store, name))
        # The protocol counts a single streamed frame as a sequence of 1; the store calls streaming
        # a sequence of 0 and plays sequences of 2 slots or more.
        seq_len = ethernet.settings.sequence_length
        m.d.comb += [
            store.bit_depth.eq(ethernet.settings.bit_depth),
            store.sequence_length.eq(Mux(seq_len > 1, seq_len, 0)),
            store.entries.eq(ethernet.settings.entries),
            store.loop.eq(ethernet.settings.loop[0]),
            store.sequence_start.eq(ethernet.sequence_start),
        ]
        wiring.connect(m, ethernet.entries, store.entry_writes)
        wiring.connect(m, store.mcb_write, wiring.flipped(self.mcb_write))
        wiring.connect(m, store.mcb_read, wiring.flipped(self.mcb_read))

        # ---- Frame hand-over and the DLPC410 sequencer (dmd) ------------------------------------
        m.submodules.broker = broker = DomainRenamer("dmd")(FrameBroker(dmd, slots=self._slots))
        wiring.connect(m, broker.ask, store.ask)
        wiring.connect(m, store.frames, broker.offered)
        wiring.connect(m, broker.store_occupancy, store.occupancy)
        m.d.comb += broker.store_lost.eq(store.lost)

        m.submodules.sequencer = seq = DomainRenamer("dmd")(Sequencer(dmd, beats=self._beats,
                                                                      store_words=store_words))
        wiring.connect(m, broker.frames, seq.frames)
        m.d.comb += [seq.occupancy.eq(broker.occupancy), broker.occ_slot.eq(seq.occ_slot)]
        wiring.connect(m, seq.requests, store.requests)
        wiring.connect(m, store.planes, seq.words)
        wiring.connect(m, seq.release, store.release)
        m.d.comb += seq.store_lost.eq(store.lost)
        wiring.connect(m, seq.pins, wiring.flipped(self.dlpc))
        m.d.comb += [
            seq.trigger_in.eq(self.trigger_in),
            seq.sync_in.eq(self.sync_in),
            self.sync_out.eq(seq.sync_out),
            self.camera_out.eq(seq.camera_out),
            self.gate_out.eq(seq.gate_out),
            self.ready_out.eq(seq.ready),
        ]
        m.submodules.soft_trigger = soft = PulseSynchronizer(i_domain="sync", o_domain="dmd")
        # a tiled display's board: its clock kept at the sync master's rate, the pulse on one edge
        m.submodules.clock_trim = trim = DomainRenamer("dmd")(ClockTrim(sampled=self._sync_pad_sampled))
        m.d.comb += [trim.sync_in.eq(self.sync_in_fall if self._sync_pad_sampled else self.sync_in),
                     trim.now.eq(seq.status.now[:16]),
                     trim.period.eq(Mux(seq.regs.trigger == TriggerMode.SYNC, seq.regs.period, 0)),
                     self.vcxo_trim.eq(trim.trim)]

        # ---- The sequencer's registers and arming (sync -> dmd) -------------------------------
        m.submodules.registers = registers = RegisterCrossing(self._regs, armed=self._armed)
        wiring.connect(m, ethernet.registers, registers.sets)
        m.d.comb += [registers.at_rest.eq(seq.at_rest), seq.reload.eq(registers.reload)]
        # Disarmed, no trigger source reaches the sequencer: the trigger mode reads as software
        # (the register crossing's output) and the software trigger is held low (a trigger pin
        # edge then does nothing either); and frames are not chained, so a chained run ends
        # with the frame that is playing and the sequencer comes to rest (where waiting register
        # sets apply).
        armed = Signal(init=self._armed)
        m.submodules.armed_cdc = FFSynchronizer(ethernet.settings.armed[0], armed, o_domain="dmd",
                                                init=self._armed)
        m.d.comb += [
            registers.armed.eq(armed),
            seq.regs.eq(registers.regs),
            soft.i.eq(ethernet.trigger),
            seq.soft_trigger.eq(soft.o & armed),
        ]

        # ---- Status: what the status reply reports, carried into sync ---------------------------
        self._report(m, ethernet, phy, store, broker, seq, registers, trim)
        return m

    def _report(self, m, ethernet, phy, store, broker, seq, registers, trim):
        """The status reply's fields: the sequencer's, the register crossing's and the clock
        loop's counts carried from ``dmd`` into ``sync`` (:class:`CountSynchronizer`), the store's
        counters, the DLPC410's and the PHY's state, and the frame shown last."""
        status = ethernet.status
        report_port(m, ethernet, status, self._sync_hz)
        for name, source in (("triggers", seq.status.triggers), ("trigger_overruns", seq.status.overruns),
                             ("frames_shown", seq.status.frames), ("triggers_early", seq.status.early),
                             ("triggers_held", seq.status.held),
                             ("rst_active_late", seq.status.rst_late),
                             ("rst_active_faults", seq.status.rst_faults),
                             ("dlpc410_restarts", seq.status.restarts),
                             ("rst_active_cycles_max", seq.status.rst_longest),
                             ("frames_period_short", seq.status.period_short),
                             ("triggers_after_end", seq.status.after_end),
                             ("pulses_late", seq.status.late), ("row_underruns", seq.status.underruns),
                             ("frames_bad_depth", seq.status.bad_frames),
                             ("registers_applied", registers.applied)):
            sync = m.submodules[f"{name}_cdc"] = CountSynchronizer(len(source), i_domain="dmd", o_domain="sync")
            m.d.comb += [sync.i.eq(source), status[name].eq(sync.o)]
        m.d.comb += status.registers_superseded.eq(registers.superseded)
        m.submodules.clock_loop_slips_cdc = slips = CountSynchronizer(len(trim.slips), i_domain="dmd",
                                                                      o_domain="sync")
        m.submodules.clock_loop_locked_cdc = FFSynchronizer(trim.locked, status.clock_loop_locked[0])
        m.d.comb += [slips.i.eq(trim.slips), status.clock_loop_slips.eq(slips.o)]
        store_counts = store.counters
        m.d.comb += [
            status.store_frames_complete.eq(store_counts.frames_complete),
            status.store_frames_replaced.eq(store_counts.frames_replaced),
            status.store_frames_abandoned.eq(store_counts.frames_abandoned),
            status.store_calibration_losses.eq(store_counts.calibration_losses),
            status.store_frames_lost.eq(store_counts.frames_lost),
            status.store_rows_refused.eq(sum(store_counts[name] for name in (
                "rows_outside", "rows_stale", "rows_shown", "rows_duplicate", "rows_no_slot", "rows_no_base"))),
            status.store_rows_no_base.eq(store_counts.rows_no_base),
            status.sequence_entries_skipped.eq(store_counts.entries_skipped),
        ]
        # dlpc410_state: bit 0 INIT_ACTIVE, 1 RST_ACTIVE, 2 ECP2_FINISHED, 3 DDR2 calibrated,
        # 4 Ethernet link up, 5-6 link speed (2 = 1000 Mb/s)
        state = Signal(4)
        m.submodules.state_cdc = FFSynchronizer(
            Cat(self.dlpc.init_active, self.dlpc.rst_active, self.dlpc.ecp2_finished, self.mcb_read.calib_done),
            state)
        m.d.comb += status.dlpc410_state.eq(Cat(state, phy.status.up, phy.status.speed))
        m.d.comb += status.shown_frame.eq(self._shown_frame(m, broker.frames, seq))

    def _shown_frame(self, m, frames, seq):
        """The frame shown last (:attr:`shown`, ``dmd``) and its id in ``sync``: the frame the
        sequencer took last, when its count of frames started steps (a frame's first clocking
        pulse), with the registers' ``lsb`` then. The sequencer takes a frame before its first
        pulse and only a newer one replaces it there, so the frame that starts is the one taken
        last (a repeat keeps its id)."""
        taken = Signal(FrameInfo)
        counted, shown_id = Signal(), Signal(FRAME_BITS)
        with m.If(frames.valid & frames.ready):
            m.d.dmd += taken.eq(frames.payload)
        # the count of frames started steps by one at most a cycle (its CountSynchronizer needs
        # that), so it has stepped exactly when its lowest bit has changed: no wide comparison
        m.d.dmd += counted.eq(seq.status.frames[0])
        started = seq.status.frames[0] != counted
        with m.If(started):
            m.d.dmd += [self.shown.number.eq(self.shown.number + 1), self.shown.frame.eq(taken.frame_id),
                        self.shown.depth.eq(taken.bit_depth), self.shown.lsb.eq(seq.regs.lsb)]
        m.submodules.shown_cdc = crossing = AsyncQueue(FRAME_BITS, 4, w_domain="dmd", r_domain="sync",
                                                       staged=("dmd",))
        m.d.comb += [crossing.w_stream.valid.eq(started), crossing.w_stream.payload.eq(taken.frame_id),
                     crossing.r_stream.ready.eq(1)]
        with m.If(crossing.r_stream.valid):
            m.d.sync += shown_id.eq(crossing.r_stream.payload)
        return shown_id
