"""The sync master's own build: :class:`SyncMasterCore` (the master and its network port) on the Atlys.

A tiled display's main control board. Its pins sit on the Atlys's VHDCI connector (LVCMOS33, a
bank the board's jumper sets to 3.3 V): one sync line and one ready line per projector board, the
frame trigger in and the camera trigger out. Every output leaves from a flip-flop in its pad
(``io.FFBuffer``, packed into the IOB by ISE), so that the sync pulses to the boards differ only by
the pads' and the cables' skew. The board's 88E1111 PHY is its network port: a host sets the
master's configuration and triggers it with master control records and reads its pulses and
refusals in master status replies (``docs/protocol.md``). Clocks: ``sync`` and ``gmii_tx`` at
125 MHz from a PLL on the board's 100 MHz oscillator, ``gmii_rx`` from the PHY.

At power-up the master is disarmed, in EXTERNAL mode, with the build's frame timing (the trigger
period, the shortest frame period the boards keep and the pulse width); the host changes them.
Button 0 is a software trigger (obeyed in SOFTWARE mode, as the host's). The LEDs show the
boards' ready lines, each pulse and each refusal (for a board not ready, for a trigger too
early) toggles one, and the last shows the master armed.
"""

from amaranth import Cat, ClockDomain, Elaboratable, Module, Signal
from amaranth.build import Attrs, Pins, Resource
from amaranth.lib import io, wiring
from amaranth.lib.cdc import FFSynchronizer
from amaranth.lib.wiring import In, Out
from amaranth_boards.atlys import AtlysPlatform

from gateware.compose import forward, members
from gateware.mac import gmii
from gateware.mac.mdio import StatusPoller
from gateware.platform.clocks import Spartan6Clocks
from gateware.platform.pins import GmiiPins
from gateware.protocol.master import MasterEndpoint, master_config_init
from gateware.protocol.port import EthernetPort, report_port
from gateware.registers import TriggerMode
from gateware.sync.master import SyncMaster
from spec import records

__all__ = ["SyncMasterCore", "SyncMasterPlatform", "SyncMasterTop", "board_core", "sync_master_resources", "BOARDS",
           "SYNC_HZ", "MASTER_ADDRESSES", "MASTER_MAX_FRAME"]

#: Projector boards the build drives (the four-DMD projector).
BOARDS = 4
#: The ``sync`` domain: the PLL's 125 MHz (the GMII's byte rate).
SYNC_HZ = Spartan6Clocks.frequencies(None)["sync"]
#: The master's network addresses (build parameters).
MASTER_ADDRESSES = dict(mac=0x02_44_4D_00_00_F0, ip=0xC0_A8_01_09, port=5000)
#: Longest frame the master's MAC takes (FCS included): its records are short, so a standard
#: frame with a VLAN tag; longer ones are dropped whole and counted (``mac_oversize``).
MASTER_MAX_FRAME = 1522
#: The PHY's reset and management lines, the poller's ports the core takes as its own.
_PHY_LINES = ("phy_reset_n", "mdc", "mdio_o", "mdio_oe", "mdio_i")
#: VHDCI pins (single-ended) for each board's sync line and ready line, the trigger and the camera.
_SYNC_PINS = ("1", "3", "4", "6")
_READY_PINS = ("35", "37", "38", "40")
_TRIGGER_PIN, _CAMERA_PIN = "7", "41"


def sync_master_resources(boards=BOARDS):
    """The sync master's pins on the VHDCI connector: fast 12 mA outputs (cables to the boards)."""
    out = Attrs(IOSTANDARD="LVCMOS33", SLEW="FAST", DRIVE="12")
    inp = Attrs(IOSTANDARD="LVCMOS33")
    return [
        *[Resource("board_sync", k, Pins(_SYNC_PINS[k], dir="o", conn=("vhdci", 0)), out) for k in range(boards)],
        *[Resource("board_ready", k, Pins(_READY_PINS[k], dir="i", conn=("vhdci", 0)), inp) for k in range(boards)],
        Resource("frame_trigger_in", 0, Pins(_TRIGGER_PIN, dir="i", conn=("vhdci", 0)), inp),
        Resource("camera_trigger_out", 0, Pins(_CAMERA_PIN, dir="o", conn=("vhdci", 0)), out),
    ]


class SyncMasterPlatform(AtlysPlatform):
    """The Atlys with the sync master's pins."""
    resources = AtlysPlatform.resources + sync_master_resources()


class SyncMasterCore(wiring.Component):
    """The sync master (:class:`~gateware.sync.master.SyncMaster`) behind its network port: what
    the board's top wires to its pins. Domains: ``sync`` (the master, the protocol), ``gmii_rx``
    and ``gmii_tx``.

    Parameters
    ----------
    boards : int
    config : dict
        The configuration at reset (:func:`~gateware.protocol.master.master_config_init`; times in
        ``sync`` cycles).
    mac, ip, port : int
        Network addresses.
    sync_hz : float
        The ``sync`` clock (reported in status replies; the PHY's management timing).
    mdio_cycles : (int, int) or None
        The PHY's reset and settle times in cycles (None: the facts table's; a simulation
        shortens them).

    Members
    -------
    gmii_rx : In(gmii.RxPins)
    gmii_tx : Out(gmii.TxPins)
    phy_reset_n, mdc, mdio_o, mdio_oe : Out(1); mdio_i : In(1)
        PHY reset and management.
    trigger_in : In(1)
        The frame trigger pin (asynchronous).
    button : In(1)
        A software trigger, on its rising edge (asynchronous: a push button).
    ready : In(boards)
        The boards' ready lines (asynchronous).
    sync_out : Out(boards); camera_out : Out(1)
        The master's pulses (registers: the platform puts them in the pads).
    armed : Out(1)
        Triggers are obeyed.
    pulses, not_ready, early : Out(32)
        The master's counts (also in the status reply).
    """

    def __init__(self, boards=BOARDS, *, config, mac, ip, port, sync_hz=SYNC_HZ, mdio_cycles=None):
        self._boards, self._sync_hz = boards, sync_hz
        self._mdio_cycles = mdio_cycles or (None, None)
        self._endpoint = MasterEndpoint(config, mac=mac, ip=ip, port=port)
        self._master = SyncMaster(boards)
        self._phy = StatusPoller(sync_hz, reset_cycles=self._mdio_cycles[0], settle_cycles=self._mdio_cycles[1])
        super().__init__({
            "gmii_rx": In(gmii.RxPins),
            "gmii_tx": Out(gmii.TxPins),
            **members(self._phy, _PHY_LINES),
            "trigger_in": In(1),
            "button": In(1),
            "ready": In(boards),
            "sync_out": Out(boards),
            "camera_out": Out(1),
            "armed": Out(1),
            "pulses": Out(32), "not_ready": Out(32), "early": Out(32),
        })

    def elaborate(self, platform):
        m = Module()
        m.submodules.ethernet = ethernet = EthernetPort(self._endpoint, max_frame=MASTER_MAX_FRAME, rx_depth=4096)
        m.d.comb += [ethernet.gmii_rx.eq(self.gmii_rx), self.gmii_tx.eq(ethernet.gmii_tx)]
        m.submodules.phy = self._phy
        forward(m, self, self._phy, _PHY_LINES)

        # the master obeys the configuration in force; a host's trigger or the button's edge
        m.submodules.master = master = self._master
        settings = ethernet.settings
        button, was = Signal(), Signal()
        m.submodules.button_sync = FFSynchronizer(self.button, button)
        m.d.sync += was.eq(button)
        m.d.comb += [
            master.mode.eq(TriggerMode(settings.mode[:len(master.mode.as_value())])),
            master.run.eq(settings.armed[0]), master.period.eq(settings.period),
            master.min_period.eq(settings.min_period), master.width.eq(settings.width),
            master.trigger_in.eq(self.trigger_in), master.ready.eq(self.ready),
            master.soft.eq(ethernet.trigger | (button & ~was)),
            self.sync_out.eq(master.sync_out), self.camera_out.eq(master.camera_out),
            self.armed.eq(settings.armed[0]),
            self.pulses.eq(master.pulses), self.not_ready.eq(master.not_ready), self.early.eq(master.early),
        ]

        # the status reply: the master's counts, its boards' ready lines, what it obeys
        status = ethernet.status
        report_port(m, ethernet, status, self._sync_hz)
        m.d.comb += [status.boards.eq(self._boards), status.ready.eq(master.ready_seen),
                     status.pulses.eq(master.pulses), status.not_ready.eq(master.not_ready),
                     status.early.eq(master.early),
                     *[status[name].eq(settings[name]) for name, _ in records.MASTER_CONFIG]]
        return m


def board_core(boards=BOARDS, *, period_s=1 / 400, min_period_s=1 / 460, width_s=1e-6):
    """The :class:`SyncMasterCore` the board builds: disarmed, EXTERNAL, the given frame timing
    (seconds, in :data:`SYNC_HZ` cycles), at :data:`MASTER_ADDRESSES`."""
    period, min_period, width = (round(t * SYNC_HZ) for t in (period_s, min_period_s, width_s))
    config = master_config_init(mode=TriggerMode.EXTERNAL, armed=False, period=period, min_period=min_period,
                                width=width)
    return SyncMasterCore(boards, config=config, **MASTER_ADDRESSES)


class SyncMasterTop(Elaboratable):
    """:class:`SyncMasterCore` on :class:`SyncMasterPlatform`.

    Parameters
    ----------
    boards : int
    period_s, min_period_s, width_s : float
        The configuration at power-up (:func:`board_core`; a host changes it): the periodic
        trigger's period, the shortest frame period the boards keep (a trigger sooner after the
        last pulse is refused), and each pulse's width.
    """

    def __init__(self, boards=BOARDS, **timing):
        assert boards <= len(_SYNC_PINS)
        self._boards, self._timing = boards, timing

    def elaborate(self, platform):
        m = Module()
        boards = self._boards

        # clocks: sync and gmii_tx from the PLL, gmii_rx from the PHY
        m.submodules.clk_buf = clk_buf = io.Buffer("i", platform.request(platform.default_clk, dir="-"))
        m.submodules.rst_buf = rst_buf = io.Buffer("i", platform.request(platform.default_rst, dir="-"))
        m.domains += [*Spartan6Clocks.domains(None), ClockDomain("gmii_rx")]
        m.submodules.clocks = clocks = Spartan6Clocks(clk_buf.i, rst_buf.i, None, platform.default_clk_frequency)
        m.submodules.gmii = pins = GmiiPins(clocks.locked)

        m.submodules.core = core = board_core(boards, **self._timing)
        pins.connect(m, core)

        # the outputs from flip-flops in their pads
        for k in range(boards):
            m.submodules[f"sync{k}"] = pad = io.FFBuffer("o", platform.request("board_sync", k, dir="-"))
            m.d.comb += pad.o.eq(core.sync_out[k])
        m.submodules.camera = camera = io.FFBuffer("o", platform.request("camera_trigger_out", 0, dir="-"))
        m.d.comb += camera.o.eq(core.camera_out)

        def pins_of(direction, name, count):
            """Resource ``name`` 0..count-1 through plain buffers: their values, or their drives."""
            values = []
            for k in range(count):
                m.submodules[f"{name}_{k}"] = buffer = io.Buffer(direction, platform.request(name, k, dir="-"))
                values.append(buffer.i if direction == "i" else buffer.o)
            return Cat(values)

        # the inputs are asynchronous: the core synchronises them
        ready = pins_of("i", "board_ready", boards)
        m.d.comb += [core.ready.eq(ready), core.trigger_in.eq(pins_of("i", "frame_trigger_in", 1)),
                     core.button.eq(pins_of("i", "button", 1))]

        # LEDs: the ready lines, a toggle per pulse and per refusal, armed
        toggles = Cat(counter[0] for counter in (core.pulses, core.not_ready, core.early))
        m.d.comb += pins_of("o", "led", 8).eq(Cat(ready, toggles, core.armed))
        return m
