"""The MAC with AXI4-Stream and GMII port names, the shape of common vendor MACs.

These wrappers only rename: :class:`AxisReceiver` is :class:`path.ReceivePath` with its frame
stream as ``m_axis_tdata/tvalid/tready/tlast/tuser`` and its pins as ``gmii_rxd/gmii_rx_dv/
gmii_rx_er``; :class:`AxisTransmitter` is :class:`path.TransmitPath` with ``s_axis_*`` and
``gmii_txd/gmii_tx_en/gmii_tx_er``. The generated Verilog then has the port list of a vendor
tri-mode MAC's user side, so either can stand in for the other. Clocks and resets are those of
the domains: ``gmii_rx_clk``/``gmii_rx_rst``, ``gmii_tx_clk``/``gmii_tx_rst`` and ``clk``/``rst``
(``sync``, the AXI-Stream side).
"""

from amaranth import Module
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from .gmii_rx import counters_layout
from .path import ReceivePath, TransmitPath

__all__ = ["AxisReceiver", "AxisTransmitter"]


class AxisReceiver(wiring.Component):
    """Receive MAC with an AXI4-Stream master (``sync``) and GMII receive pins (``gmii_rx``).

    Parameters are those of :class:`path.ReceivePath`.

    Members
    -------
    gmii_rxd : In(8)
    gmii_rx_dv : In(1)
    gmii_rx_er : In(1)
    m_axis_tdata : Out(8)
    m_axis_tvalid : Out(1)
    m_axis_tready : In(1)
    m_axis_tlast : Out(1)
    m_axis_tuser : Out(1)
        Set with ``tlast`` on a bad frame.
    counters : Out(:func:`gmii_rx.counters_layout`)
        Frames per verdict, in ``sync``.
    dropped : Out(counter_width)
        Frames dropped for lack of room, in ``sync``.
    """

    def __init__(self, *, counter_width=32, **params):
        self._path = ReceivePath(counter_width=counter_width, **params)
        super().__init__({
            "gmii_rxd": In(8), "gmii_rx_dv": In(1), "gmii_rx_er": In(1),
            "m_axis_tdata": Out(8), "m_axis_tvalid": Out(1), "m_axis_tready": In(1),
            "m_axis_tlast": Out(1), "m_axis_tuser": Out(1),
            "counters": Out(counters_layout(counter_width)),
            "dropped": Out(counter_width),
        })

    def elaborate(self, platform):
        m = Module()
        m.submodules.path = path = self._path
        frames = path.frames
        m.d.comb += [
            path.gmii.d.eq(self.gmii_rxd), path.gmii.dv.eq(self.gmii_rx_dv), path.gmii.er.eq(self.gmii_rx_er),
            self.m_axis_tdata.eq(frames.payload.data),
            self.m_axis_tvalid.eq(frames.valid),
            frames.ready.eq(self.m_axis_tready),
            self.m_axis_tlast.eq(frames.payload.last),
            self.m_axis_tuser.eq(frames.payload.user),
            self.counters.eq(path.counters),
            self.dropped.eq(path.dropped),
        ]
        return m


class AxisTransmitter(wiring.Component):
    """Transmit MAC with an AXI4-Stream slave (``sync``) and GMII transmit pins (``gmii_tx``).

    Parameters are those of :class:`path.TransmitPath`.

    Members
    -------
    s_axis_tdata : In(8)
    s_axis_tvalid : In(1)
    s_axis_tready : Out(1)
    s_axis_tlast : In(1)
    s_axis_tuser : In(1)
        Set with ``tlast`` to abort the frame (sent with a bad FCS).
    gmii_txd : Out(8)
    gmii_tx_en : Out(1)
    gmii_tx_er : Out(1)
    underruns : Out(counter_width)
        Frames aborted on underrun, in ``sync``.
    """

    def __init__(self, *, counter_width=32, **params):
        self._path = TransmitPath(counter_width=counter_width, **params)
        super().__init__({
            "s_axis_tdata": In(8), "s_axis_tvalid": In(1), "s_axis_tready": Out(1),
            "s_axis_tlast": In(1), "s_axis_tuser": In(1),
            "gmii_txd": Out(8), "gmii_tx_en": Out(1), "gmii_tx_er": Out(1),
            "underruns": Out(counter_width),
        })

    def elaborate(self, platform):
        m = Module()
        m.submodules.path = path = self._path
        frames = path.frames
        m.d.comb += [
            frames.payload.data.eq(self.s_axis_tdata),
            frames.valid.eq(self.s_axis_tvalid),
            self.s_axis_tready.eq(frames.ready),
            frames.payload.last.eq(self.s_axis_tlast),
            frames.payload.user.eq(self.s_axis_tuser),
            self.gmii_txd.eq(path.gmii.d), self.gmii_tx_en.eq(path.gmii.en), self.gmii_tx_er.eq(path.gmii.er),
            self.underruns.eq(path.underruns),
        ]
        return m
