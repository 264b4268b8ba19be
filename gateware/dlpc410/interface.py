"""The DLPC410 applications interface as a port signature (what our FPGA drives and reads).

One ``dmd`` cycle carries ``beats`` DCLK cycles: one at DCLK 200 MHz, two at 400 MHz. The core
gives each data pin's bit on every DCLK edge of the cycle (``din_<bus>[edge]``, 16 pins per bus,
edge 0 the first DCLK cycle's rising edge, then its falling edge, then the next DCLK cycle's;
mapped from bit-plane words by :mod:`gateware.dlpc410.beat`), and DVALID likewise; the platform
layer turns them into DDR outputs (ODDR2, one beat) or 4:1 serialisers (OSERDES2, two beats) and
forwards DCLK. Buses A and B exist on every DMD, C and D only when ``buses == 4`` (DLP9500).

Row cycles (how the DLPC410 model reads these signals, and how the sequencer must drive them):

* a row cycle is ``dclk_per_row`` consecutive DCLK cycles with DVALID high; consecutive row
  cycles may follow back to back while DVALID stays high; the sequencer starts row cycles on
  ``dmd`` cycle boundaries only;
* ``rowmd``, ``rowad``, ``blkmd``, ``blkad`` and ``rst2blkz`` are sampled on the first cycle of
  each row cycle and held for its length;
* the data beats of the row cycle carry the row, word 0 first;
* when DVALID falls it stays low for an even number of DCLK cycles (DLPU045A: the controller
  runs at DCLK/2).

Facts and encodings: :mod:`spec.facts`.
"""

from amaranth.lib import data, wiring
from amaranth.lib.wiring import In, Out

from spec import facts

from ..wire import hdl_enum
from .beat import PINS_PER_BUS

__all__ = ["din_layout", "Signature", "RowMode", "BlockMode", "PINS_PER_BUS"]

#: ROWMD and BLKMD encodings (:data:`spec.facts.RowMode`, :data:`spec.facts.BlockMode`).
RowMode = hdl_enum(facts.RowMode, 2)
BlockMode = hdl_enum(facts.BlockMode, 2)



def din_layout(beats):
    """One bus's pins over a ``dmd`` cycle: ``2 * beats`` edges of 16 bits, in time order."""
    return data.ArrayLayout(PINS_PER_BUS, 2 * beats)


class Signature(wiring.Signature):
    """DLPC410 applications interface, from the FPGA's side.

    Members
    -------
    din_a, din_b (, din_c, din_d) : Out(din_layout(beats))
        Data pins on every DCLK edge of the cycle.
    dvalid : Out(2 * beats)
        DVALID (on every bus) on every DCLK edge of the cycle: starts and frames row cycles.
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

    def __init__(self, buses=2, beats=1):
        assert buses in (2, 4) and beats in (1, 2)
        self.buses, self.beats = buses, beats
        members = {f"din_{b}": Out(din_layout(beats)) for b in "abcd"[:buses]}
        members.update({
            "dvalid": Out(2 * beats),
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
        return isinstance(other, Signature) and (other.buses, other.beats) == (self.buses, self.beats)

    def __repr__(self):
        return f"dlpc410.interface.Signature(buses={self.buses}, beats={self.beats})"


