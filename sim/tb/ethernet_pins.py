""":class:`gateware.protocol.port.EthernetPort` with one Verilog port per GMII pin, for cocotbext-eth.

The composition carries its pins as :class:`gateware.mac.gmii.RxPins`/``TxPins`` structs (one
packed vector each in Verilog); cocotbext-eth's ``GmiiSource``/``GmiiSink`` need a handle per
pin. This wrapper only renames; every other port passes through under its own name.
"""

from amaranth import Module
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from gateware.protocol.endpoint import Endpoint
from gateware.protocol.port import EthernetPort
from sim.models.frames import Addresses
from spec.facts import DMDS

__all__ = ["EthernetPins", "TOPLEVEL", "build"]

TOPLEVEL = "net_ethernet_port"
_PINS = {"gmii_rxd": ("gmii_rx", "d"), "gmii_rx_dv": ("gmii_rx", "dv"), "gmii_rx_er": ("gmii_rx", "er"),
         "gmii_txd": ("gmii_tx", "d"), "gmii_tx_en": ("gmii_tx", "en"), "gmii_tx_er": ("gmii_tx", "er")}


class EthernetPins(wiring.Component):
    """:class:`EthernetPort` with flat pin names (``gmii_rxd/gmii_rx_dv/gmii_rx_er`` in,
    ``gmii_txd/gmii_tx_en/gmii_tx_er`` out); the other members are the port's."""

    def __init__(self, port):
        self._port = port
        members = {name: member for name, member in port.signature.members.items()
                   if name not in ("gmii_rx", "gmii_tx")}
        members.update({"gmii_rxd": In(8), "gmii_rx_dv": In(1), "gmii_rx_er": In(1),
                        "gmii_txd": Out(8), "gmii_tx_en": Out(1), "gmii_tx_er": Out(1)})
        super().__init__(members)

    def elaborate(self, platform):
        m = Module()
        m.submodules.port = port = self._port
        for name, (pins, field) in _PINS.items():
            inner = getattr(getattr(port, pins), field)
            m.d.comb += (inner.eq(getattr(self, name)) if pins == "gmii_rx"
                         else getattr(self, name).eq(inner))
        wiring.connect(m, port.pixels, wiring.flipped(self.pixels))
        wiring.connect(m, port.registers, wiring.flipped(self.registers))
        for name in ("settings", "trigger", "mac_counters", "rx_dropped", "tx_underruns",
                     "net_counters", "app_counters"):
            m.d.comb += getattr(self, name).eq(getattr(port, name))
        m.d.comb += port.status.eq(self.status)
        return m


def build(dmd="dlp7000"):
    """The port as tested and benchmarked: the shipping geometry, the test addresses."""
    a = Addresses()
    return EthernetPins(EthernetPort(Endpoint(DMDS[dmd], mac=a.mac, ip=a.ip, port=a.port)))
