"""The DLPC410 applications interface as a port signature (what our FPGA drives and reads).

One ``dmd`` cycle is one DCLK period. The core gives each data pin's rising- and falling-edge
bit per cycle (``din_<bus>.rise``/``.fall``, 16 pins per bus, mapped from bit-plane words by
:mod:`gateware.dlpc410.beat`); the platform layer turns them into DDR outputs (ODDR2) and
forwards DCLK. Buses A and B exist on every DMD, C and D only when ``buses == 4`` (DLP9500).

Row cycles (how the DLPC410 model reads these signals, and how the sequencer must drive them):

* a row cycle is ``dclk_per_row`` consecutive cycles with ``dvalid`` high; consecutive row
  cycles may follow back to back while ``dvalid`` stays high;
* ``rowmd``, ``rowad``, ``blkmd``, ``blkad`` and ``rst2blkz`` are sampled on the first cycle of
  each row cycle and held for its length;
* the data beats of the row cycle carry the row, word 0 first;
* when ``dvalid`` falls it stays low for an even number of cycles (DLPU045A: the controller
  runs at DCLK/2).

Facts and encodings: :mod:`spec.facts`.
"""

from amaranth.lib import data, wiring
from amaranth.lib.wiring import In, Out

from spec import facts

from ..wire import hdl_enum

__all__ = ["DinPair", "Signature", "RowMode", "BlockMode"]

#: ROWMD and BLKMD encodings (:data:`spec.facts.RowMode`, :data:`spec.facts.BlockMode`).
RowMode = hdl_enum(facts.RowMode, 2)
BlockMode = hdl_enum(facts.BlockMode, 2)


class DinPair(data.Struct):
    rise: 16
    fall: 16


class Signature(wiring.Signature):
    """DLPC410 applications interface, from the FPGA's side.

    Members
    -------
    din_a, din_b (, din_c, din_d) : Out(DinPair)
        Data pins, both DCLK edges.
    dvalid : Out(1)
        Starts and frames row cycles (drives DVALID on every bus).
    rowmd : Out(RowMode), rowad : Out(11)
        Row mode and address.
    blkmd : Out(BlockMode), blkad : Out(4), rst2blkz : Out(1)
        Block command, address, and dual/quad selector (high = default).
    comp_data, ns_flip, wdt_enblz, pwr_float, arstz : Out(1)
        Complement data, north/south flip, watchdog enable (low), mirror park, controller reset (low).
    init_active, rst_active, ecp2_finished : In(1)
        Controller status.
    dmd_type : In(4), ddc_version : In(3)
        DMD identification.
    """

    def __init__(self, buses=2):
        assert buses in (2, 4)
        self.buses = buses
        members = {f"din_{b}": Out(DinPair) for b in "abcd"[:buses]}
        members.update({
            "dvalid": Out(1),
            "rowmd": Out(RowMode),
            "rowad": Out(11),
            "blkmd": Out(BlockMode),
            "blkad": Out(4),
            "rst2blkz": Out(1, init=1),
            "comp_data": Out(1),
            "ns_flip": Out(1),
            "wdt_enblz": Out(1, init=1),
            "pwr_float": Out(1),
            "arstz": Out(1),
            "init_active": In(1),
            "rst_active": In(1),
            "ecp2_finished": In(1),
            "dmd_type": In(4),
            "ddc_version": In(3),
        })
        super().__init__(members)

    def __eq__(self, other):
        return isinstance(other, Signature) and other.buses == self.buses

    def __repr__(self):
        return f"dlpc410.interface.Signature(buses={self.buses})"


