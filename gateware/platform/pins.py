"""Pin adapters: the core's ports to the board's pins, with the Spartan-6 I/O primitives.

The core gives plain signals per clock cycle; here they become IOB registers, DDR outputs
(ODDR2) and LVDS buffers. Nothing here is simulated with the core: the core simulates without
vendor primitives, and these adapters are checked by building the Spartan-6 tree.
"""

from amaranth import ClockSignal, Const, Elaboratable, Instance, Module, ResetSignal, Signal
from amaranth.lib import io
from amaranth.lib.cdc import FFSynchronizer, ResetSynchronizer

from gateware.dlpc410.interface import Signature as Dlpc410Signature
from gateware.mac.gmii import RxPins, TxPins

from .serdes import DCLK_BITS, Oserdes4, lane_bits

__all__ = ["GmiiPins", "Dlpc410Pins", "TriggerPins"]


class GmiiPins(Elaboratable):
    """The 88E1111's GMII and management pins.

    Drives ``ClockSignal("gmii_rx")`` from RX_CLK (the top owns the ``gmii_rx`` domain),
    registers the receive pins in the IOBs on RX_CLK and the transmit pins on ``gmii_tx``, and
    forwards ``gmii_tx``'s clock to GTX_CLK through an ODDR2 so that it leaves the FPGA with the
    same delay as the data.

    Parameters
    ----------
    locked : Signal
        The PLL's lock: ``gmii_rx`` is held in reset until it is set.

    Attributes
    ----------
    rx : Signal(RxPins), in ``gmii_rx``
    tx : Signal(TxPins), in ``gmii_tx``
    phy_reset_n, mdc, mdio_o, mdio_oe : Signal, driven by the core
    mdio_i : Signal, to the core
    """

    def __init__(self, locked):
        self._locked = locked
        self.rx = Signal(RxPins)
        self.tx = Signal(TxPins)
        self.phy_reset_n = Signal()
        self.mdc = Signal()
        self.mdio_o = Signal()
        self.mdio_oe = Signal()
        self.mdio_i = Signal()

    def elaborate(self, platform):
        m = Module()
        pins = platform.request("eth_gmii", 0, dir="-")

        m.submodules.rx_clk = rx_clk = io.Buffer("i", pins.rx_clk)
        m.submodules.rx_bufg = Instance("BUFG", i_I=rx_clk.i, o_O=ClockSignal("gmii_rx"))
        platform.add_clock_constraint(rx_clk.i, 125e6)
        m.submodules.rx_rst = ResetSynchronizer(~self._locked, domain="gmii_rx")
        for name, port, target in (("rx_data", pins.rx_data, self.rx.d), ("rx_dv", pins.rx_dv, self.rx.dv),
                                   ("rx_er", pins.rx_er, self.rx.er)):
            m.submodules[name] = buf = io.FFBuffer("i", port, i_domain="gmii_rx")
            m.d.comb += target.eq(buf.i)

        for name, port, value in (("tx_data", pins.tx_data, self.tx.d), ("tx_en", pins.tx_en, self.tx.en),
                                  ("tx_er", pins.tx_er, self.tx.er)):
            m.submodules[name] = buf = io.FFBuffer("o", port, o_domain="gmii_tx")
            m.d.comb += buf.o.eq(value)
        m.submodules.gtx_clk = gtx = io.DDRBuffer("o", pins.gtx_clk, o_domain="gmii_tx")
        m.d.comb += [gtx.o[0].eq(1), gtx.o[1].eq(0)]

        m.submodules.phy_rst = rst = io.Buffer("o", pins.rst)
        m.submodules.mdc = mdc = io.Buffer("o", pins.mdc)
        m.submodules.mdio = mdio = io.Buffer("io", pins.mdio)
        m.d.comb += [
            rst.o.eq(~self.phy_reset_n),     # the resource's pin is active low already
            mdc.o.eq(self.mdc),
            mdio.o.eq(self.mdio_o),
            mdio.oe.eq(self.mdio_oe),
        ]
        m.submodules.mdio_sync = FFSynchronizer(mdio.i, self.mdio_i)
        return m


class Dlpc410Pins(Elaboratable):
    """The DLPC410 interface on the adapter board's pins.

    DCLK 400 MHz (two beats a ``dmd`` cycle): data and DVALID leave through 4:1 OSERDES2s
    (:mod:`.serdes`: four edges a cycle, edge 0 first), DCLK through one more whose I/O clock is
    half a bit later. DCLK 200 MHz (one beat): data and DVALID through ODDR2s clocked by ``dmd``
    (rising-edge bit first), DCLK forwarded from ``dclk``, 90 degrees later. Either way DCLK's
    edges sit in the middle of each bit. Inputs are registered in the IOBs and synchronised into
    ``dmd``.

    On a board without the adapter's second port (``platform.dlpc410_complete`` false) only
    bus A, DCLK and DVALID exist: the core's other outputs go nowhere and ECP2_FINISHED reads
    low, so the sequencer never leaves its initialisation wait.

    Parameters
    ----------
    buses, beats : int
        As :class:`gateware.dlpc410.interface.Signature`'s.
    io : dict
        At two beats, :attr:`gateware.platform.clocks.Spartan6Clocks.io`: the BUFPLLs' I/O clocks
        and strobes for the data lanes and for DCLK.

    Attributes
    ----------
    bus : interface of :class:`gateware.dlpc410.interface.Signature`, flipped: the core drives it
    """

    def __init__(self, buses=2, beats=1, io=None):
        assert beats == 1 or io, "two beats a cycle need the serialisers' I/O clocks"
        self._beats, self._io = beats, io or {}
        self.bus = Dlpc410Signature(buses, beats).flip().create()

    def _lanes(self, m, name, port, edges):
        """A pin bus (``port``, one pin per bit) sending ``edges`` (per edge, one bit per pin)."""
        if self._beats == 1:
            m.submodules[name] = buf = io.DDRBuffer("o", port, o_domain="dmd")
            m.d.comb += [buf.o[0].eq(edges[0]), buf.o[1].eq(edges[1])]
            return
        ioclk, strobe = self._io["data"]
        for pin in range(len(port)):
            m.submodules[f"{name}_{pin}"] = buf = io.Buffer("o", port[pin])
            m.submodules[f"{name}_{pin}_serdes"] = Oserdes4(
                lane_bits(edges, pin), ioclk=ioclk, strobe=strobe, reset=ResetSignal("dmd"), out=buf.o)

    def _dclk(self, m, name, port):
        if self._beats == 1:
            m.submodules[name] = buf = io.DDRBuffer("o", port, o_domain="dclk")
            m.d.comb += [buf.o[0].eq(1), buf.o[1].eq(0)]
            return
        ioclk, strobe = self._io["dclk"]
        m.submodules[name] = buf = io.Buffer("o", port)
        m.submodules[f"{name}_serdes"] = Oserdes4([Const(b) for b in DCLK_BITS], ioclk=ioclk, strobe=strobe,
                                                  reset=ResetSignal("dmd"), out=buf.o)

    def elaborate(self, platform):
        m = Module()
        bus = self.bus
        fast = platform.request("dlpc410", 0, dir="-")
        self._lanes(m, "din_a", fast.din_a, bus.din_a)
        for clk in ("dclk_a", "dclk_b"):
            self._dclk(m, clk, getattr(fast, clk))
        for valid in ("dvalid_a", "dvalid_b"):
            self._lanes(m, valid, getattr(fast, valid), [bus.dvalid[e] for e in range(2 * self._beats)])

        if not getattr(platform, "dlpc410_complete", False):
            return m

        ext = platform.request("dlpc410_ext", 0, dir="-")
        self._lanes(m, "din_b", ext.din_b, bus.din_b)
        for name in ("rowmd", "rowad", "blkmd", "blkad", "rst2blkz", "comp_data", "ns_flip",
                     "wdt_enblz", "pwr_float", "arstz"):
            m.submodules[name] = buf = io.FFBuffer("o", getattr(ext, name), o_domain="dmd")
            m.d.comb += buf.o.eq(getattr(bus, name))
        for name in ("init_active", "rst_active", "ecp2_finished", "dmd_type", "ddc_version"):
            m.submodules[name] = buf = io.FFBuffer("i", getattr(ext, name), i_domain="dmd")
            m.submodules[f"{name}_sync"] = FFSynchronizer(buf.i, getattr(bus, name), o_domain="dmd")
        return m


class TriggerPins(Elaboratable):
    """Trigger and sync in (IOB registers on ``dmd``), sync out, camera-trigger out and the
    ready line to a sync master (IOB registers).

    The inputs' IOB registers are the first synchronising stage; the core adds the rest.

    Attributes
    ----------
    trigger, sync_in : Signal, to the core (``dmd``, one IOB stage, not yet synchronised)
    sync, camera, ready : Signal, from the core
    """

    def __init__(self):
        self.trigger = Signal()
        self.sync_in = Signal()
        self.sync = Signal()
        self.camera = Signal()
        self.ready = Signal()

    def elaborate(self, platform):
        m = Module()

        def pad(direction, name):
            buffer = io.FFBuffer(direction, platform.request(name, 0, dir="-"),
                                 **{f"{direction}_domain": "dmd"})
            m.submodules[name] = buffer
            return buffer
        trig, sync_in = pad("i", "trigger_in"), pad("i", "sync_in")
        sync, cam, ready = pad("o", "sync_out"), pad("o", "camera_trigger_out"), pad("o", "ready_out")
        m.d.comb += [self.trigger.eq(trig.i), self.sync_in.eq(sync_in.i), sync.o.eq(self.sync),
                     cam.o.eq(self.camera), ready.o.eq(self.ready)]
        return m


