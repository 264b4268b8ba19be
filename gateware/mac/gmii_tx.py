"""MAC transmit: frames (destination MAC .. payload) in, GMII bytes out.

Each frame goes out as seven preamble bytes and the SFD, its bytes, zero padding up to 60 bytes
(64 with the FCS), and the FCS from :mod:`amaranth.lib.crc`; the next frame starts no sooner than
the minimum inter-frame gap after it. A frame whose ``last`` byte has ``user`` set leaves with
its FCS inverted, so every receiver drops it.

The input must not run dry inside a frame (:class:`cdc.TxCrossing` offers a frame only once it
is buffered). If it does, the MAC asserts ``tx_er`` for one byte, which the PHY turns into an
error the far end counts, ends the frame, discards the rest of it from the input and counts an
underrun.
"""

from amaranth import DomainRenamer, Module, Signal
from amaranth.lib import stream, wiring
from amaranth.lib.wiring import In, Out

from . import gmii
from .layouts import ByteBeat

__all__ = ["Transmitter"]

#: Bytes before the FCS in the shortest frame; shorter frames are padded with zeros.
_MIN_DATA = gmii.MIN_FRAME_BYTES - gmii.FCS_BYTES
#: Preamble plus SFD.
_HEAD = gmii.PREAMBLE_BYTES + 1


class Transmitter(wiring.Component):
    """GMII transmit MAC.

    Parameters
    ----------
    gap : int
        Idle bytes between frames on the pins, at least the standard 12.
    counter_width : int
    domain : str
        The transmit clock domain; every port lives in it.

    Members
    -------
    frames : In(stream.Signature(:class:`ByteBeat`))
        Frames to send. A frame is started when ``valid`` is seen; its bytes are then taken one
        per cycle after the preamble.
    gmii : Out(:class:`gmii.TxPins`)
        ``tx_d``, ``tx_en``, ``tx_er``, registered.
    underruns : Out(counter_width)
        Frames cut short because ``valid`` fell inside them.
    """

    def __init__(self, *, gap=gmii.MIN_GAP_BYTES, counter_width=32, domain="gmii_tx"):
        assert gap >= gmii.MIN_GAP_BYTES
        self._gap = gap
        self._domain = domain
        super().__init__({
            "frames": In(stream.Signature(ByteBeat)),
            "gmii": Out(gmii.TxPins),
            "underruns": Out(counter_width),
        })

    def elaborate(self, platform):
        m = Module()
        tx = self._domain
        m.submodules.fcs = fcs = DomainRenamer(tx)(gmii.fcs_parameters().create())

        # What goes on the pins next cycle; registered below.
        pins = Signal(gmii.TxPins)
        m.d[tx] += self.gmii.eq(pins)

        # Preamble or FCS byte index; data bytes so far (saturating at the padded length).
        index = Signal(range(_HEAD))
        sent = Signal(range(_MIN_DATA + 1))
        abort = Signal()
        # Idle cycles since the last frame, up to the one before the preamble (the output
        # register adds one); the reset value lets the first frame go at once.
        quiet = Signal(range(self._gap), init=self._gap - 1)

        beat = self.frames.payload

        def send(byte):
            m.d.comb += [pins.d.eq(byte), pins.en.eq(1)]

        def count_data():
            m.d.comb += fcs.valid.eq(1)
            with m.If(sent != _MIN_DATA):
                m.d[tx] += sent.eq(sent + 1)

        with m.FSM(domain=tx):
            with m.State("IDLE"):
                with m.If(quiet != self._gap - 1):
                    m.d[tx] += quiet.eq(quiet + 1)
                with m.Elif(self.frames.valid):
                    m.d[tx] += index.eq(0)
                    m.next = "PREAMBLE"

            with m.State("PREAMBLE"):
                with m.If(index == _HEAD - 1):
                    send(gmii.SFD_BYTE)
                    m.d.comb += fcs.start.eq(1)
                    m.d[tx] += sent.eq(0)
                    m.next = "DATA"
                with m.Else():
                    send(gmii.PREAMBLE_BYTE)
                m.d[tx] += index.eq(index + 1)

            with m.State("DATA"):
                m.d.comb += self.frames.ready.eq(1)
                with m.If(self.frames.valid):
                    send(beat.data)
                    m.d.comb += fcs.data.eq(beat.data)
                    count_data()
                    with m.If(beat.last):
                        m.d[tx] += [abort.eq(beat.user), index.eq(0)]
                        with m.If(sent < _MIN_DATA - 1):
                            m.next = "PAD"
                        with m.Else():
                            m.next = "FCS"
                with m.Else():
                    # Underrun: poison the frame on the wire and drop its remainder.
                    send(0)
                    m.d.comb += pins.er.eq(1)
                    m.d[tx] += self.underruns.eq(self.underruns + 1)
                    m.next = "DRAIN"

            with m.State("PAD"):
                send(0)
                m.d.comb += fcs.data.eq(0)
                count_data()
                with m.If(sent == _MIN_DATA - 1):
                    m.next = "FCS"

            with m.State("FCS"):
                # The CRC register holds still here (no ``valid``), one byte out per cycle.
                send(fcs.crc.word_select(index[:2], 8) ^ abort.replicate(8))
                m.d[tx] += index.eq(index + 1)
                with m.If(index == gmii.FCS_BYTES - 1):
                    m.d[tx] += quiet.eq(0)
                    m.next = "IDLE"

            with m.State("DRAIN"):
                m.d.comb += self.frames.ready.eq(1)
                with m.If(self.frames.valid & beat.last):
                    m.d[tx] += quiet.eq(0)
                    m.next = "IDLE"

        return m
