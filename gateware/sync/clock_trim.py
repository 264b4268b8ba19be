"""A board's self-calibrating clock: a phase-locked loop from the sync master's pulses to the
board's voltage-controlled crystal (VCXO).

Boards of a tiled display each run on their own crystal, up to 100 ppm apart; a frame restarts
on the master's pulse, but within it a board's planes drift from the others' by their clocks'
difference (100 ppm over a 3.5 ms frame is 350 ns). This loop trims the board's oscillator so
that it keeps the master's rate, and places the pulse's edge half a cycle before the rising edge
that samples it, so that every board takes the pulse on the same edge of its own clock.

* The phase detector samples the sync line on the *falling* clock edge (a falling-edge flip-flop
  in the input pad, then a synchroniser) and reads the time base when the pulse arrives, against
  where it is expected: ``period`` cycles after the last one (16-bit arithmetic, modulo 2**16:
  the error only ever needs a few cycles). Its error is ``-(2 * phase + 1)``: never zero, so
  that once locked the loop holds the edge at the falling edge, dithering across it by a small
  fraction of a cycle, and the rising edge half a cycle later takes it without doubt.
* The first pulse sets the expected times on even cycles of the time base: the sequencer's bus
  decides on even cycles, so every board starts its frame on the same cycle after the pulse.
* A proportional and an integral term, each a power of two chosen from the period (a longer
  period sees more drift per pulse: ``kp = 23 - bit_length(period)``, ``ki = kp - 4``, found by
  the loop's model, :mod:`sim.models.clock_trim_model`), saturated to 15 bits each and summed into the
  16-bit ``trim`` word a DAC turns into the VCXO's control voltage.
* A pulse more than ``CAPTURE`` cycles from where it was expected (a pulse missed, the master
  restarted) is a slip: counted, and the next pulse sets the expected times again.

Everything after the detector is registered steps after each pulse (pulses come thousands of
cycles apart): the terms are doubled a step a cycle, and the gains' search takes a bit of the
period a cycle, so that no path is deeper than a few LUTs or has a chain over 16 bits.
"""

from amaranth import Cat, ClockDomain, ClockSignal, Const, Module, Mux, ResetSignal, Signal, signed
from amaranth.lib import wiring
from amaranth.lib.cdc import FFSynchronizer
from amaranth.lib.wiring import In, Out

from ..counter import Counter
from ..dlpc410.layouts import COUNTER_BITS
from ..registers import DURATION_BITS

__all__ = ["ClockTrim", "CAPTURE", "TRIM_BITS", "gains"]

#: Bits of the trim word (the DAC's).
TRIM_BITS = 16
#: The largest phase error (cycles) the loop works with; beyond it a pulse is a slip.
CAPTURE = 1024
#: Pulses in a row with the edge within a cycle of the falling edge before ``locked``.
LOCK_PULSES = 15
_TERM = 15          # bits of each term
#: The gains' shifts: ``kp = KP_LENGTH - bit_length(period)``, ``ki = kp - KI_BELOW`` (each 0..15).
KP_LENGTH, KI_BELOW = 23, 4


def gains(period):
    """``(kp, ki)``: the loop's shifts for a period of ``period`` cycles, as the gateware forms
    them."""
    kp = min(max(KP_LENGTH - period.bit_length(), 0), 15)
    return kp, max(kp - KI_BELOW, 0)


class ClockTrim(wiring.Component):
    """The board's clock, phase-locked to the sync master's pulses (domain ``sync``).

    Parameters
    ----------
    sampled : bool
        ``sync_in`` is already the line's sample on the falling edge, taken in the input pad (a
        DDR input register's falling half, presented in this domain: on a board, where the
        sequencer takes the rising half of the same register); otherwise the loop samples the
        line on the falling edge itself.

    Members
    -------
    sync_in : In(1)
        The master's sync line (asynchronous), or its falling-edge sample (``sampled``).
    now : In(16)
        The time base's low bits (the sequencer's ``status.now``: its parity is the bus's).
    period : In(DURATION_BITS)
        Cycles between the master's pulses at the nominal clock; 0: the loop is off.
    trim : Out(signed(TRIM_BITS))
        The VCXO's control word: positive speeds the clock up. 0 while off.
    phase : Out(signed(16))
        The last pulse's arrival less its expected cycle.
    locked : Out(1)
        The last :data:`LOCK_PULSES` pulses each came within a cycle of the falling edge, and
        meanwhile the edge crossed it twice: it dithers across it, no longer sweeping through
        the cycle as the frequency settles.
    pulses, slips : Out(COUNTER_BITS)
        Pulses seen; pulses beyond :data:`CAPTURE` cycles of their expected time.
    """
    sync_in: In(1)
    now: In(16)
    period: In(DURATION_BITS)
    trim: Out(signed(TRIM_BITS))
    phase: Out(signed(16))
    locked: Out(1)
    pulses: Out(COUNTER_BITS)
    slips: Out(COUNTER_BITS)

    def __init__(self, *, sampled=False):
        self._sampled = sampled
        super().__init__()

    def elaborate(self, platform):
        m = Module()
        # the detector: the falling edge's sample (the pad's, or taken here), then a synchroniser
        synced, last = Signal(), Signal()
        if self._sampled:
            sampled = self.sync_in
        else:
            m.domains.fall = ClockDomain("fall", clk_edge="neg", local=True)
            m.d.comb += [ClockSignal("fall").eq(ClockSignal("sync")), ResetSignal("fall").eq(ResetSignal("sync"))]
            sampled = Signal()
            m.d.fall += sampled.eq(self.sync_in)
        m.submodules.synchroniser = FFSynchronizer(sampled, synced, stages=2)
        m.d.sync += last.eq(synced)
        edge = synced & ~last

        # the gains, from the period: it holds still while the loop runs, so its length (its
        # highest set bit) is found a bit a cycle, over and over, and the gains registered
        period, on = Signal(DURATION_BITS), Signal()
        scan, count, length = Signal(DURATION_BITS), Signal(range(DURATION_BITS + 1)), Signal(range(DURATION_BITS + 1))
        kp, ki = Signal(4), Signal(4)
        m.d.sync += [period.eq(self.period), on.eq(period != 0)]
        with m.If(scan != 0):
            m.d.sync += [scan.eq(scan >> 1), count.eq(count + 1)]
        with m.Else():
            m.d.sync += [length.eq(count), scan.eq(period), count.eq(0)]
        m.d.sync += [kp.eq(_clamp(m, KP_LENGTH - length, "kp")), ki.eq(_clamp(m, kp - KI_BELOW, "ki"))]

        expected, anchored, anchoring = Signal(16), Signal(), Signal()
        stage = Signal(3)               # one-hot: the registered steps after a pulse
        error = Signal(signed(_TERM))   # -(2 * phase + 1), within the capture range
        integral = Signal(signed(_TERM))
        good = Signal(range(LOCK_PULSES + 1))
        crossings, side = Signal(2), Signal()       # the edge crossed the falling edge (saturates at 2)
        m.d.comb += self.locked.eq((good == LOCK_PULSES) & (crossings == 2))

        m.d.sync += [stage.eq(stage << 1), anchoring.eq(0)]
        m.submodules.pulse_count = pulse_count = Counter(COUNTER_BITS)
        m.submodules.slip_count = slip_count = Counter(COUNTER_BITS)
        m.d.comb += [self.pulses.eq(pulse_count.count), self.slips.eq(slip_count.count),
                     pulse_count.inc.eq(edge & on)]
        with m.If(edge & on):
            with m.If(~anchored):
                # the first pulse: expected times on even cycles (rounded up, then a period on)
                m.d.sync += [expected.eq(self.now + self.now[0]), anchored.eq(1), anchoring.eq(1)]
            with m.Else():
                m.d.sync += [self.phase.eq(self.now - expected), expected.eq(expected + period[:16]),
                             stage.eq(1)]
        with m.If(anchoring):
            m.d.sync += expected.eq(expected + period[:16])
        # 1: within the capture range? -(2 * phase + 1) is the bits of 2 * phase inverted
        with m.If(stage[0]):
            top_bits = self.phase[10:]
            with m.If((top_bits == 0) | (top_bits == (1 << len(top_bits)) - 1)):
                m.d.sync += error.eq(~Cat(Const(0, 1), self.phase[:11], self.phase[15].replicate(_TERM - 12)))
                with m.If((self.phase == 0) | (self.phase == -1)):
                    m.d.sync += side.eq(self.phase[0])
                    with m.If(good != LOCK_PULSES):
                        m.d.sync += good.eq(good + 1)
                    with m.If((good != 0) & (side != self.phase[0]) & (crossings != 2)):
                        m.d.sync += crossings.eq(crossings + 1)
                with m.Else():
                    m.d.sync += [good.eq(0), crossings.eq(0)]
            with m.Else():
                m.d.comb += slip_count.inc.eq(1)
                m.d.sync += [anchored.eq(0), stage.eq(0), good.eq(0), crossings.eq(0)]
        # 2: the integral, saturated
        total = Signal(signed(_TERM + 1))
        m.d.comb += total.eq(integral + error)
        with m.If(stage[1]):
            with m.If(total[-1] != total[-2]):          # beyond 15 bits: the sign says which way
                m.d.sync += integral.eq(Mux(total[-1], _BOTTOM, _TOP))
            with m.Else():
                m.d.sync += integral.eq(total)
        # 3..: each term doubled, saturated, a step a cycle until scaled by its gain; then summed
        proportional, integrated = Signal(signed(_TERM)), Signal(signed(_TERM))
        steps_p, steps_i, shifting = Signal(4), Signal(4), Signal()
        with m.If(stage[2]):
            m.d.sync += [proportional.eq(error), integrated.eq(integral), steps_p.eq(kp), steps_i.eq(ki),
                         shifting.eq(1)]
        with m.Elif(shifting):
            for term, steps in ((proportional, steps_p), (integrated, steps_i)):
                with m.If(steps != 0):
                    m.d.sync += [term.eq(_doubled(term)), steps.eq(steps - 1)]
            with m.If((steps_p == 0) & (steps_i == 0)):
                m.d.sync += [self.trim.eq(proportional + integrated), shifting.eq(0)]
        with m.If(~on):
            m.d.sync += [anchored.eq(0), integral.eq(0), self.trim.eq(0), good.eq(0), crossings.eq(0), stage.eq(0),
                         shifting.eq(0)]
        return m


_TOP, _BOTTOM = (1 << (_TERM - 1)) - 1, -(1 << (_TERM - 1))


def _doubled(value):
    """``2 * value`` clamped to the term's range: it overflows when its top two bits differ."""
    return Mux(value[-1] != value[-2], Mux(value[-1], _BOTTOM, _TOP), value << 1)


def _clamp(m, value, name):
    """``value`` clamped to 0..15."""
    out = Signal(4, name=name)
    with m.If(value < 0):
        m.d.comb += out.eq(0)
    with m.Elif(value > 15):
        m.d.comb += out.eq(15)
    with m.Else():
        m.d.comb += out.eq(value)
    return out
