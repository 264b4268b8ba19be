"""The store's recovery from a memory that lost its calibration (``sync`` domain).

When the MCB's ``calib_done`` falls after it had risen, the controller has been reset and DDR2
has gone without refresh: every stored word is lost, and so are the commands and words in the
port FIFOs. From that cycle the store is *lost*: the writer drops what it holds and what still
arrives of rows begun before (no MCB traffic), the slot table holds new rows back and, between
rows, forgets every frame (counted), and the reader answers the sequencer's outstanding requests
with zeros (its own side, :class:`~gateware.store.reader.Reader`). The store is whole again
once the memory is calibrated and the table has forgotten: it forgets between rows and holds
rows back from then on, so the writer has been given no word since, and every row stored after
is written after the calibration.

Before the first calibration nothing is lost: the writer waits for it, as it always has.
"""

from amaranth import Module
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

__all__ = ["Recovery"]


class Recovery(wiring.Component):
    """Watch ``calib_done`` and say when the store's contents are lost.

    Members
    -------
    calib_done : In(1)
        The write port's ``calib_done``.
    forgotten : In(1)
        The slot table has forgotten every frame since the loss.
    lost : Out(1)
        The memory's contents are lost and the store has not recovered yet; high in the very
        cycle ``calib_done`` falls.
    """

    calib_done: In(1)
    forgotten: In(1)
    lost: Out(1)

    def elaborate(self, platform):
        m = Module()
        with m.FSM(name="recovery"):
            with m.State("FIRST"):
                with m.If(self.calib_done):
                    m.next = "KEPT"
            with m.State("KEPT"):
                m.d.comb += self.lost.eq(~self.calib_done)
                with m.If(~self.calib_done):
                    m.next = "LOST"
            with m.State("LOST"):
                m.d.comb += self.lost.eq(1)
                with m.If(self.calib_done & self.forgotten):
                    m.next = "KEPT"
        return m
