"""The PCS receive process (IEEE 802.3 clause 36.2.5.2.2, figure 36-7): code-groups to GMII.

In sync, /S/ (K27.7) starts a frame and is given as a preamble byte (0x55): it took the first
one's place. Data code-groups in a frame are its bytes; /T/ (K29.7) ends it. A K28.5 in an even
position in a frame ends it with ``rx_er`` (the standard's EARLY_END: an ordered set began);
any other code-group in a frame, /V/ or invalid, is a byte with ``rx_er``. Losing sync inside
a frame ends it with ``rx_er``. Between frames K28.5 followed by D21.5 or D2.2 is a
configuration ordered set (/C1/, /C2/), whose 16-bit word, low byte first, is given on
``configs``; K28.5 with another data code-group is an idle, given on ``idle``; an invalid
code-group between frames is given on ``invalid``. These three are clause 36's RUDI(/C/),
RUDI(/I/) and RUDI(INVALID), for auto-negotiation.

Not done: the look-ahead past /T/ for /R/ (``check_end``), carrier extension, and false carrier
(``rx_er`` with 0x0E outside a frame).
"""

from amaranth import Module
from amaranth.lib import data, stream, wiring
from amaranth.lib.wiring import In, Out

from .code_groups import K28_5, CodeGroup
from .transmit import ORDERED_SETS

__all__ = ["Receiver", "RxPins"]

#: What a receiver gives for /S/ (clause 36.2.5.2.2): the preamble byte it replaced.
PREAMBLE_BYTE = 0x55


class RxPins(data.Struct):
    """GMII receive pins, as the MAC samples them."""
    d: 8
    dv: 1
    er: 1


class Receiver(wiring.Component):
    """Decoded code-groups in sync in, GMII out.

    Members
    -------
    group : In(:class:`CodeGroup`)
        The synchroniser's code-group, one every cycle.
    even : In(1)
        ``group`` is in an even position.
    sync_status : In(1)
        The link is in sync; out of sync nothing is received.
    gmii : Out(:class:`RxPins`)
        ``rx_d``, ``rx_dv``, ``rx_er`` for the code-group of the cycle before; ``rx_d`` is 0
        when ``rx_dv`` is low.
    configs : Out(stream.Signature(16, always_ready=True))
        Each configuration word received, the cycle after its last byte; the link partner's
        auto-negotiation base page or next page (clause 37.2.1).
    idle : Out(1)
        An /I/ was received, the cycle after its second code-group.
    invalid : Out(1)
        An invalid code-group was received in sync between frames, the cycle after it.
    """

    group: In(CodeGroup)
    even: In(1)
    sync_status: In(1)
    gmii: Out(RxPins)
    configs: Out(stream.Signature(16, always_ready=True))
    idle: Out(1)
    invalid: Out(1)

    def elaborate(self, platform):
        m = Module()
        cg = self.group
        valid = ~cg.invalid()
        data_cg = valid & ~cg.control

        def control(name):
            return valid & cg.control & (cg.data == ORDERED_SETS[name])

        k28_5 = valid & cg.control & (cg.data == K28_5)
        configuring = data_cg & ((cg.data == ORDERED_SETS["C1"]) | (cg.data == ORDERED_SETS["C2"]))

        def give(byte, error=0):
            m.d.sync += [self.gmii.d.eq(byte), self.gmii.dv.eq(1), self.gmii.er.eq(error)]

        m.d.sync += [self.gmii.eq(0), self.configs.valid.eq(0), self.idle.eq(0), self.invalid.eq(0)]
        with m.FSM() as fsm:
            with m.State("IDLE"):
                with m.If(self.sync_status & k28_5):
                    m.next = "K"
                with m.Elif(self.sync_status & control("S")):
                    give(PREAMBLE_BYTE)
                    m.next = "FRAME"
            with m.State("K"):
                with m.If(self.sync_status & configuring):
                    m.next = "CONFIG_LOW"
                with m.Else():
                    m.d.sync += self.idle.eq(self.sync_status & data_cg)
                    m.next = "IDLE"
            with m.State("CONFIG_LOW"):
                m.d.sync += self.configs.payload[:8].eq(cg.data)
                m.next = "CONFIG_HIGH"
            with m.State("CONFIG_HIGH"):
                m.d.sync += self.configs.payload[8:].eq(cg.data)
                m.d.sync += self.configs.valid.eq(self.sync_status)
                m.next = "IDLE"
            with m.State("FRAME"):
                with m.If(~self.sync_status):
                    give(cg.data, error=1)
                    m.next = "IDLE"
                with m.Elif(control("T")):
                    m.next = "IDLE"
                with m.Elif(k28_5 & self.even):
                    give(cg.data, error=1)
                    m.next = "K"
                with m.Elif(data_cg):
                    give(cg.data)
                with m.Else():
                    give(cg.data, error=1)
        with m.If(~fsm.ongoing("FRAME")):
            m.d.sync += self.invalid.eq(self.sync_status & ~valid)
        return m
