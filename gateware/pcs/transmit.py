"""The PCS transmit process (IEEE 802.3 clause 36.2.5.2.1-2, figures 36-5 and 36-6): GMII bytes
to code-groups.

Between frames the transmitter sends idles, /I1/ (K28.5 D5.6) when the running disparity is
positive, which turns it negative, else /I2/ (K28.5 D16.2), which keeps it so: every K28.5
after the first idle goes out from a negative running disparity. An ordered set begins on an
even code-group. A frame goes out as /S/ (K27.7) in place of its first byte, its bytes, /V/
(K30.7) for a byte with ``tx_er``, and /T/R/ (K29.7 K23.7) after it, with one more /R/ when
the /T/R/ ended on an even code-group, so that the next idle starts on an even one. ``tx_en``
rising in the second code-group of an idle loses that byte to the idle (a preamble byte): the
next is sent as /S/.

With ``configuring`` set the transmitter sends configuration ordered sets in place of idles,
/C1/ (K28.5 D21.5) and /C2/ (K28.5 D2.2) in turn, each followed by the 16-bit word low byte
first (clause 36.2.4.10): what auto-negotiation (clause 37, not here) sends.
"""

from amaranth import Module, Signal
from amaranth.lib import data, wiring
from amaranth.lib.wiring import In, Out

from .code_groups import K28_5, Encoder

__all__ = ["Transmitter", "TxPins", "ORDERED_SETS"]

#: The control code-groups of the ordered sets (Table 36-3) and the data code-groups that follow
#: K28.5 in /I1/, /I2/, /C1/, /C2/.
ORDERED_SETS = {"S": 0xFB, "T": 0xFD, "R": 0xF7, "V": 0xFE, "I1": 0xC5, "I2": 0x50, "C1": 0xB5, "C2": 0x42}


class TxPins(data.Struct):
    """GMII transmit pins, as the MAC drives them."""
    d: 8
    en: 1
    er: 1


class Transmitter(wiring.Component):
    """GMII in, one code-group a cycle out.

    Members
    -------
    gmii : In(:class:`TxPins`)
        The MAC's ``tx_d``, ``tx_en``, ``tx_er``; the PCS cannot stall it. ``tx_er`` without
        ``tx_en`` (carrier extension, a half-duplex matter) is ignored.
    configuring : In(1)
        Send /C/ ordered sets carrying ``config`` in place of idles.
    config : In(16)
    code : Out(10)
        The code-group for the cycle before's pins, ``a`` in bit 0, for the transceiver.
    even : Out(1)
        ``code`` is in an even position.
    """

    gmii: In(TxPins)
    configuring: In(1)
    config: In(16)
    code: Out(10)
    even: Out(1)

    def elaborate(self, platform):
        m = Module()
        m.submodules.encoder = encoder = Encoder()
        m.d.comb += self.code.eq(encoder.code)
        pins = self.gmii
        # The position of the code-group the encoder takes now.
        even = Signal(init=1)
        m.d.sync += [even.eq(~even), self.even.eq(even)]
        second = Signal()  # /C2/ next

        def send(byte, control=0):
            m.d.comb += [encoder.data.eq(byte), encoder.control.eq(control)]

        with m.FSM():
            with m.State("IDLE"):
                with m.If(even & pins.en & ~pins.er & ~self.configuring):
                    send(ORDERED_SETS["S"], 1)
                    m.next = "DATA"
                with m.Else():
                    send(K28_5, 1)
                    with m.If(self.configuring):
                        m.next = "CONFIG"
                    with m.Else():
                        m.next = "IDLE_D"
            with m.State("IDLE_D"):
                # Negative after K28.5: it was positive, so /I1/ to turn it back.
                with m.If(encoder.disparity):
                    send(ORDERED_SETS["I2"])
                with m.Else():
                    send(ORDERED_SETS["I1"])
                m.next = "IDLE"
            with m.State("CONFIG"):
                with m.If(second):
                    send(ORDERED_SETS["C2"])
                with m.Else():
                    send(ORDERED_SETS["C1"])
                m.d.sync += second.eq(~second)
                m.next = "CONFIG_LOW"
            with m.State("CONFIG_LOW"):
                send(self.config[:8])
                m.next = "CONFIG_HIGH"
            with m.State("CONFIG_HIGH"):
                send(self.config[8:])
                m.next = "IDLE"
            with m.State("DATA"):
                with m.If(~pins.en):
                    send(ORDERED_SETS["T"], 1)
                    m.next = "END"
                with m.Elif(pins.er):
                    send(ORDERED_SETS["V"], 1)
                with m.Else():
                    send(pins.d)
            with m.State("END"):
                send(ORDERED_SETS["R"], 1)
                # /R/ now even: the next code-group is odd, so one more /R/.
                with m.If(even):
                    m.next = "ALIGN"
                with m.Else():
                    m.next = "IDLE"
            with m.State("ALIGN"):
                send(ORDERED_SETS["R"], 1)
                m.next = "IDLE"
        return m
