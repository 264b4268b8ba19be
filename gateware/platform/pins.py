"""Pin adapters: the core's ports to the board's pins, with the Spartan-6 I/O primitives.

The core gives plain signals per clock cycle; here they become IOB registers, DDR outputs
(ODDR2) and LVDS buffers. Nothing here is simulated with the core: the core simulates without
vendor primitives, and these adapters are checked by building the Spartan-6 tree.
"""

from amaranth import ClockDomain, ClockSignal, Const, Elaboratable, Instance, Module, Mux, ResetSignal, Signal
from amaranth.lib import io, wiring
from amaranth.lib.cdc import FFSynchronizer, ResetSynchronizer
from amaranth.lib.wiring import In, Out

from gateware.dlpc410.interface import Signature as Dlpc410Signature
from gateware.mac.gmii import RxPins, TxPins

from .serdes import DCLK_BITS, Oserdes4, lane_bits

__all__ = ["GmiiPins", "SfpGmiiPins", "SfpPhy", "GmiiTxElastic", "Dlpc410Pins", "TriggerPins", "VcxoDacPins"]

class EthernetPins(Elaboratable):
    """What the core's MAC sees of the Ethernet PHY, whichever it is: GMII and management.

    The board's PHY block drives ``ClockSignal("gmii_rx")`` (the top owns the ``gmii_rx``
    domain) and holds it in reset until ``locked``.

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

    #: The management lines, by the names a core's ports and these attributes share.
    MANAGEMENT = ("phy_reset_n", "mdc", "mdio_o", "mdio_oe")

    def __init__(self, locked):
        self._locked = locked
        self.rx = Signal(RxPins)
        self.tx = Signal(TxPins)
        self.phy_reset_n = Signal()
        self.mdc = Signal()
        self.mdio_o = Signal()
        self.mdio_oe = Signal()
        self.mdio_i = Signal()

    def connect(self, m, core):
        """Wire ``core``'s GMII and management ports (``gmii_rx``, ``gmii_tx``, ``phy_reset_n``,
        ``mdc``, ``mdio_o``, ``mdio_oe``, ``mdio_i``) to this PHY."""
        m.d.comb += [core.gmii_rx.eq(self.rx), self.tx.eq(core.gmii_tx), core.mdio_i.eq(self.mdio_i),
                     *[getattr(self, name).eq(getattr(core, name)) for name in self.MANAGEMENT]]


class GmiiPins(EthernetPins):
    """The 88E1111's GMII and management pins (the Atlys).

    Drives ``ClockSignal("gmii_rx")`` from RX_CLK, registers the receive pins in the IOBs on
    RX_CLK and the transmit pins on ``gmii_tx``, and forwards ``gmii_tx``'s clock to GTX_CLK
    through an ODDR2 so that it leaves the FPGA with the same delay as the data.
    """

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


class SfpGmiiPins(EthernetPins):
    """Gigabit Ethernet through an SFP cage (the SVEC): a GMII PHY inside the FPGA.

    The PHY is our 1000BASE-X PCS (:class:`gateware.pcs.Pcs`, 8b/10b and auto-negotiation in
    fabric) on one lane of the SFP's GTP transceiver (:class:`.gtp.Gtp`, 10 bits a cycle at
    1.25 Gb/s), keeping the 88E1111's GMII contract: the receive side runs on the GTP's recovered
    clock, which drives ``ClockSignal("gmii_rx")``, and its outputs are registered once on
    ``gmii_rx`` as the 88E1111's are in the IOBs; the transmit side runs on the GTP's transmit
    user clock (``sfp_tx``, from the SFP's 125 MHz reference), into which :class:`GmiiTxElastic`
    carries ``gmii_tx``, dropping or adding idle cycles between frames so that the two 125 MHz
    clocks may differ by their tolerance.

    There is no MDIO PHY: MDIO reads all ones (the core's PHY poller reads the 88E1111's
    register 17, which a 1000BASE-X PCS does not have).
    """

    def elaborate(self, platform):
        m = Module()
        sfp = platform.request("sfp", 0, dir="-")
        refclk = platform.request("sfp_refclk", 0, dir="-")
        m.submodules.phy = phy = SfpPhy(sfp, refclk)
        m.d.comb += [phy.reset.eq(~self.phy_reset_n), phy.locked.eq(self._locked), phy.tx.eq(self.tx),
                     self.rx.eq(phy.rx)]
        m.submodules.tx_disable = tx_disable = io.Buffer("o", sfp.tx_disable)
        m.d.comb += [tx_disable.o.eq(0), self.mdio_i.eq(1)]
        return m


class SfpPhy(wiring.Component):
    """The SFP's GMII PHY in the FPGA: the GTP lane, our PCS and the transmit elastic buffer.

    Drives ``ClockSignal("gmii_rx")`` from the GTP's recovered clock and holds ``gmii_rx`` in
    reset until ``locked`` and the GTP is ready; ``gmii_tx`` is the caller's. The PCS's own
    domains (``sfp_tx``, ``sfp_rx``) are local.

    Parameters
    ----------
    pads, refclk :
        As :class:`.gtp.Gtp`'s: the SFP's ``tx``, ``rx`` pairs and its reference clock pair.
    link_timer : int
        Auto-negotiation's link timer in cycles (10 ms nominal; shorter in simulation).

    Members
    -------
    reset : In(1)
        Holds the GTP in reset.
    locked : In(1)
        The fabric's clocks are locked.
    tx : In(TxPins), in ``gmii_tx``
    rx : Out(RxPins), in ``gmii_rx``, registered once
    sync_status, mr_an_complete, losses, slips, restarts, xmit : Out
        The PCS's, in ``gmii_rx``.
    """

    def __init__(self, pads, refclk, *, link_timer=1_250_000, counter_width=16):
        from gateware.pcs.autoneg import Xmit
        self._pads, self._refclk, self._link_timer, self._counter_width = pads, refclk, link_timer, counter_width
        super().__init__({
            "reset": In(1), "locked": In(1), "tx": In(TxPins), "rx": Out(RxPins),
            "sync_status": Out(1), "mr_an_complete": Out(1), "xmit": Out(Xmit),
            "losses": Out(counter_width), "slips": Out(counter_width), "restarts": Out(counter_width),
        })

    def elaborate(self, platform):
        from gateware.pcs import Pcs

        from .gtp import Gtp
        m = Module()
        m.domains += [ClockDomain("sfp_tx", local=True), ClockDomain("sfp_rx", local=True)]
        m.submodules.gtp = gtp = Gtp(self._pads, self._refclk, self.reset, tx_domain="sfp_tx", rx_domain="sfp_rx")
        m.submodules.pcs = pcs = Pcs(tx_domain="sfp_tx", rx_domain="sfp_rx", link_timer=self._link_timer,
                                     counter_width=self._counter_width)
        m.d.comb += [pcs.rx_bits.eq(gtp.rx_bits), gtp.tx_code.eq(pcs.tx_code)]
        m.submodules.tx_elastic = elastic = GmiiTxElastic("gmii_tx", "sfp_tx")
        m.d.comb += [elastic.i.eq(self.tx), pcs.gmii_tx.eq(elastic.o)]

        m.d.comb += ClockSignal("gmii_rx").eq(ClockSignal("sfp_rx"))
        m.submodules.rx_rst = ResetSynchronizer(~(self.locked & gtp.ready), domain="gmii_rx")
        m.d.gmii_rx += self.rx.eq(pcs.gmii_rx)
        m.d.comb += [getattr(self, name).eq(getattr(pcs, name))
                     for name in ("sync_status", "mr_an_complete", "xmit", "losses", "slips", "restarts")]
        return m


class GmiiTxElastic(Elaboratable):
    """GMII transmit words from ``i_domain`` to ``o_domain``, two clocks of the same nominal rate.

    Every word passes through a small asynchronous FIFO; idle words (``en`` low) are dropped on
    the way in while it is fuller than ``high``, and idle words are added on the way out, between
    frames only, while it holds fewer than ``low``. A frame, once started, is read a word every
    cycle.

    Attributes
    ----------
    i : Signal(TxPins), in ``i_domain``
    o : Signal(TxPins), in ``o_domain``, registered
    """

    def __init__(self, i_domain, o_domain, *, depth=16, low=6, high=11):
        self._i_domain, self._o_domain, self._depth, self._low, self._high = i_domain, o_domain, depth, low, high
        self.i = Signal(TxPins)
        self.o = Signal(TxPins)

    def elaborate(self, platform):
        from amaranth.lib.fifo import AsyncFIFO
        m = Module()
        m.submodules.fifo = fifo = AsyncFIFO(width=len(self.i.as_value()), depth=self._depth,
                                             r_domain=self._o_domain, w_domain=self._i_domain)
        m.d.comb += [fifo.w_data.eq(self.i), fifo.w_en.eq(self.i.en | (fifo.w_level < self._high))]
        primed, in_frame = Signal(), Signal()
        head = Signal(TxPins)
        m.d.comb += head.eq(fifo.r_data)
        read = Signal()
        m.d.comb += read.eq(fifo.r_rdy & primed & (in_frame | (fifo.r_level >= self._low)))
        m.d.comb += fifo.r_en.eq(read)
        with m.If(fifo.r_level >= self._low):
            m.d[self._o_domain] += primed.eq(1)
        m.d[self._o_domain] += [self.o.eq(Mux(read, fifo.r_data, 0)), in_frame.eq(read & head.en)]
        return m


class Dlpc410Pins(Elaboratable):
    """The DLPC410 interface on the adapter board's pins.

    DCLK 400 MHz (two beats a ``dmd`` cycle): data and DVALID leave through 4:1 OSERDES2s
    (:mod:`.serdes`: four edges a cycle, edge 0 first), DCLK through one more whose I/O clock is
    half a bit later. DCLK 200 MHz (one beat): data and DVALID through ODDR2s clocked by ``dmd``
    (rising-edge bit first), DCLK forwarded from ``dclk``, 90 degrees later. Either way DCLK's
    edges sit in the middle of each bit. Inputs are registered in the IOBs and synchronised into
    ``dmd``.

    The adapter's pins are the board's resources ``dlpc410`` and ``dlpc410_ext``
    (:mod:`.dlpc410_adapter`), each bus's DIN, DCLK and DVALID in whichever holds them. On a
    board without the adapter's second port (``platform.dlpc410_complete`` false) only what
    ``dlpc410`` holds is driven (on the Atlys: bus A, the DCLKs and DVALIDs): the core's other
    outputs go nowhere and ECP2_FINISHED reads low, so the sequencer never leaves its
    initialisation wait. A DMD with more buses than the board's adapter carries
    (``platform.dlpc410_buses``) is refused.

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
        self._buses, self._beats, self._io = buses, beats, io or {}
        self.bus = Dlpc410Signature(buses, beats).flip().create()

    @staticmethod
    def check(platform, buses):
        """Refuse a DMD of more ``buses`` than the board's adapter carries."""
        carried = getattr(platform, "dlpc410_buses", 2)
        if buses > carried:
            raise ValueError(f"the board's DLPC410 adapter carries {carried} buses, the DMD needs {buses}")

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
        self.check(platform, self._buses)
        complete = getattr(platform, "dlpc410_complete", False)
        groups = [platform.request(name, 0, dir="-") for name in ("dlpc410", "dlpc410_ext")[:1 + complete]]

        # each group's DIN lanes, then its DCLKs, then its DVALIDs
        letters = "abcd"[:self._buses]
        driven = set()
        for group in groups:
            for kind in ("din", "dclk", "dvalid"):
                for name in (f"{kind}_{letter}" for letter in letters):
                    port = getattr(group, name, None)
                    if port is None:
                        continue
                    if kind == "din":
                        self._lanes(m, name, port, getattr(bus, name))
                    elif kind == "dclk":
                        self._dclk(m, name, port)
                    else:
                        self._lanes(m, name, port, [bus.dvalid[e] for e in range(2 * self._beats)])
                    driven.add(name)
        if not complete:
            return m
        missing = {f"{kind}_{letter}" for kind in ("din", "dclk", "dvalid") for letter in letters} - driven
        assert not missing, f"the adapter has no pins for {sorted(missing)}"

        ext = groups[1]
        for name in ("rowmd", "rowad", "blkmd", "blkad", "rst2blkz", "comp_data", "ns_flip",
                     "wdt_enblz", "pwr_float", "arstz"):
            m.submodules[name] = buf = io.FFBuffer("o", getattr(ext, name), o_domain="dmd")
            m.d.comb += buf.o.eq(getattr(bus, name))
        for name in ("init_active", "rst_active", "ecp2_finished", "dmd_type", "ddc_version"):
            m.submodules[name] = buf = io.FFBuffer("i", getattr(ext, name), i_domain="dmd")
            m.submodules[f"{name}_sync"] = FFSynchronizer(buf.i, getattr(bus, name), o_domain="dmd")
        return m


class TriggerPins(Elaboratable):
    """Trigger in (an IOB register on ``dmd``), sync in (a DDR input register on ``dmd``: its
    rising and its falling half), sync out, camera-trigger out, the ready line to a sync
    master and, on a board that places it (``platform.light_gate``), the light gate out (IOB
    registers).

    The inputs' IOB registers are the first synchronising stage; the core adds the rest. The sync
    input's falling half is the clock loop's phase detector: the loop holds the pulse's edge at
    the falling edge, so the rising half, the sequencer's, takes it half a cycle from any change.

    Attributes
    ----------
    trigger, sync_in, sync_in_fall : Signal, to the core (``dmd``, not yet synchronised)
    sync, camera, ready, gate : Signal, from the core
    """

    def __init__(self):
        self.trigger = Signal()
        self.sync_in = Signal()
        self.sync_in_fall = Signal()
        self.sync = Signal()
        self.camera = Signal()
        self.ready = Signal()
        self.gate = Signal()

    def elaborate(self, platform):
        m = Module()

        def pad(direction, name):
            buffer = io.FFBuffer(direction, platform.request(name, 0, dir="-"),
                                 **{f"{direction}_domain": "dmd"})
            m.submodules[name] = buffer
            return buffer
        trig = pad("i", "trigger_in")
        # both halves of the sync input leave the pad together, the falling one sampled first
        m.submodules.sync_in = sync_in = io.DDRBuffer("i", platform.request("sync_in", 0, dir="-"), i_domain="dmd")
        sync, cam, ready = pad("o", "sync_out"), pad("o", "camera_trigger_out"), pad("o", "ready_out")
        m.d.comb += [self.trigger.eq(trig.i), self.sync_in.eq(sync_in.i[0]), self.sync_in_fall.eq(sync_in.i[1]),
                     sync.o.eq(self.sync),
                     cam.o.eq(self.camera), ready.o.eq(self.ready)]
        if getattr(platform, "light_gate", False):
            m.d.comb += pad("o", "light_gate_out").o.eq(self.gate)
        return m


class VcxoDacPins(Elaboratable):
    """The serial lines of the DAC that sets the board's VCXO (``vcxo_dac``: SCLK, DIN and SYNC,
    from :class:`~gateware.sync.trim_dac.TrimDac`), through IOB registers on ``dmd``: the three
    leave on the same edge, a cycle after the writer's registers.

    Attributes
    ----------
    sclk, din, sync_n : Signal, from the writer
    """

    LINES = ("sclk", "din", "sync_n")

    def __init__(self):
        self.sclk, self.din, self.sync_n = Signal(init=1), Signal(), Signal(init=1)

    def elaborate(self, platform):
        m = Module()
        dac = platform.request("vcxo_dac", 0, dir={name: "-" for name in self.LINES})
        for name in self.LINES:
            m.submodules[f"vcxo_dac_{name}"] = pad = io.FFBuffer("o", getattr(dac, name), o_domain="dmd")
            m.d.comb += pad.o.eq(getattr(self, name))
        return m
