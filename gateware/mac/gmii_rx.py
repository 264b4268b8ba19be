"""MAC receive: GMII bytes in, frames (destination MAC .. payload) with a verdict out.

Framing
-------
A frame starts on the SFD, after any number of preamble bytes, none included: PHYs may shorten
the preamble, and the FCS still guards the frame, so nothing is gained by insisting on seven. A
byte other than 0x55 before the SFD, or ``rx_dv`` falling before any SFD, is a preamble error.
``rx_er`` with ``rx_dv`` low (carrier extension, false carrier) is ignored.

Verdicts
--------
Every frame that reaches the SFD, or fails before it, gets exactly one verdict, counted in
:attr:`Receiver.counters`. When several apply, the first of this order wins: ``RX_ER`` (``rx_er``
on any byte while ``rx_dv``, the FCS included), ``OVERSIZE`` (more than ``max_frame`` bytes,
FCS included), ``RUNT`` (fewer than 64), ``BAD_FCS``, else ``GOOD``. ``PREAMBLE`` (and ``RX_ER``
inside the preamble) frames produce no output at all.

Output timing
-------------
The FCS is only known four bytes after the last data byte, so bytes leave five bytes behind the
pins (four for the FCS, one to learn that ``rx_dv`` has fallen); the last data byte then carries
``last`` and the verdict (``user`` = 1 for anything but ``GOOD``). Frames of four bytes or fewer
produce no output. Bytes beyond ``max_frame`` are not forwarded; the frame still ends, flagged bad,
when ``rx_dv`` falls.
"""

from amaranth import DomainRenamer, Module, Mux, Signal
from amaranth.lib import data, enum, stream, wiring
from amaranth.lib.wiring import In, Out

from . import gmii
from .layouts import ByteBeat

__all__ = ["Receiver", "Verdict", "counters_layout"]

#: Bytes held back so that the verdict, known after the FCS and the end of ``rx_dv``, rides on
#: the last data byte.
_HOLD = gmii.FCS_BYTES + 1


class Verdict(enum.Enum, shape=3):
    GOOD = 0
    BAD_FCS = 1
    RX_ER = 2
    RUNT = 3
    OVERSIZE = 4
    PREAMBLE = 5


def counters_layout(width=32):
    """One frame counter per verdict, named like the verdict in lower case (``good``,
    ``bad_fcs``, ``rx_er``, ``runt``, ``oversize``, ``preamble``)."""
    return data.StructLayout({verdict.name.lower(): width for verdict in Verdict})


class Receiver(wiring.Component):
    """GMII receive MAC.

    Parameters
    ----------
    max_frame : int
        Longest good frame, destination MAC to FCS inclusive.
    counter_width : int
        Width of each verdict counter (they wrap).
    domain : str
        The PHY's receive clock domain; every port lives in it.

    Members
    -------
    gmii : In(:class:`gmii.RxPins`)
        The PHY's ``rx_d``, ``rx_dv``, ``rx_er``.
    frames : Out(stream.Signature(:class:`ByteBeat`, always_ready=True))
        Destination MAC to the end of the payload, one byte per cycle while a frame arrives;
        ``user`` on the ``last`` byte is the verdict (1 = bad). GMII cannot be stalled, so there
        is no ``ready``: the consumer takes every transfer (:class:`cdc.RxCrossing` does).
    counters : Out(:func:`counters_layout`)
        Frames seen per verdict.
    """

    def __init__(self, *, max_frame=gmii.MAX_JUMBO_FRAME_BYTES, counter_width=32, domain="gmii_rx"):
        assert max_frame >= gmii.MIN_FRAME_BYTES
        self._max_frame = max_frame
        self._domain = domain
        super().__init__({
            "gmii": In(gmii.RxPins),
            "frames": Out(stream.Signature(ByteBeat, always_ready=True)),
            "counters": Out(counters_layout(counter_width)),
        })

    def elaborate(self, platform):
        m = Module()
        rx = self._domain
        m.submodules.fcs = fcs = DomainRenamer(self._domain)(gmii.fcs_parameters().create())

        # One register stage on the pins: the input flip-flops.
        pins = Signal(gmii.RxPins)
        m.d[rx] += pins.eq(self.gmii)

        # Bytes after the SFD so far (the index of the byte now on the pins), saturating past the limit.
        length = Signal(range(self._max_frame + 2))
        errored = Signal()
        # The last four bytes (a candidate FCS) and the byte before them, the next to leave.
        window = Signal(8 * gmii.FCS_BYTES)
        held = Signal(8)

        verdict = Signal(Verdict)
        counted = Signal()

        m.d[rx] += self.frames.valid.eq(0)

        def begin_frame():
            m.d.comb += fcs.start.eq(1)
            m.d[rx] += [length.eq(0), errored.eq(0)]
            m.next = "DATA"

        def reject(why):
            m.d.comb += [counted.eq(1), verdict.eq(why)]

        def emit(last, user):
            # The held byte leaves; the output is a register, valid for this one cycle.
            m.d[rx] += [
                self.frames.valid.eq(1),
                self.frames.payload.data.eq(held),
                self.frames.payload.last.eq(last),
                self.frames.payload.user.eq(user),
            ]

        with m.FSM(domain=self._domain):
            with m.State("IDLE"):
                with m.If(pins.dv):
                    with m.If(pins.er):
                        reject(Verdict.RX_ER)
                        m.next = "DISCARD"
                    with m.Elif(pins.d == gmii.SFD_BYTE):
                        begin_frame()
                    with m.Elif(pins.d == gmii.PREAMBLE_BYTE):
                        m.next = "PREAMBLE"
                    with m.Else():
                        reject(Verdict.PREAMBLE)
                        m.next = "DISCARD"

            with m.State("PREAMBLE"):
                with m.If(~pins.dv):
                    reject(Verdict.PREAMBLE)
                    m.next = "IDLE"
                with m.Elif(pins.er):
                    reject(Verdict.RX_ER)
                    m.next = "DISCARD"
                with m.Elif(pins.d == gmii.SFD_BYTE):
                    begin_frame()
                with m.Elif(pins.d != gmii.PREAMBLE_BYTE):
                    reject(Verdict.PREAMBLE)
                    m.next = "DISCARD"

            with m.State("DATA"):
                with m.If(pins.dv):
                    m.d.comb += [fcs.valid.eq(1), fcs.data.eq(pins.d)]
                    m.d[rx] += [
                        length.eq(Mux(length > self._max_frame, length, length + 1)),
                        errored.eq(errored | pins.er),
                    ]
                    with m.If(length < self._max_frame):
                        m.d[rx] += window.eq((window << 8) | pins.d)
                        with m.If(length >= _HOLD - 1):
                            m.d[rx] += held.eq(window[-8:])
                        with m.If(length >= _HOLD):
                            emit(last=0, user=0)
                with m.Else():
                    with m.If(errored):
                        m.d.comb += verdict.eq(Verdict.RX_ER)
                    with m.Elif(length > self._max_frame):
                        m.d.comb += verdict.eq(Verdict.OVERSIZE)
                    with m.Elif(length < gmii.MIN_FRAME_BYTES):
                        m.d.comb += verdict.eq(Verdict.RUNT)
                    with m.Elif(~fcs.match_detected):
                        m.d.comb += verdict.eq(Verdict.BAD_FCS)
                    with m.Else():
                        m.d.comb += verdict.eq(Verdict.GOOD)
                    m.d.comb += counted.eq(1)
                    with m.If(length >= _HOLD):
                        emit(last=1, user=verdict != Verdict.GOOD)
                    m.next = "IDLE"

            with m.State("DISCARD"):
                with m.If(~pins.dv):
                    m.next = "IDLE"

        for member in Verdict:
            counter = self.counters[member.name.lower()]
            with m.If(counted & (verdict == member)):
                m.d[rx] += counter.eq(counter + 1)

        return m
