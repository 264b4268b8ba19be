"""The VCXO's DAC: the clock loop's trim word, written to an AD5662 over its serial interface.

A tiled display board's clock loop (:class:`~gateware.sync.clock_trim.ClockTrim`) gives a signed
16-bit trim word; the DAC (:data:`spec.facts.VCXO_DAC`) takes straight binary, mid-scale at the
VCXO's nominal frequency, so its code is the trim word with the sign bit inverted. The writer
writes without end, each write the word as it was when the write began (never a word torn
between two values):

* ``sync_n`` low across 24 bits, most significant first: six don't-care bits, the power-down
  bits (00, normal), the 16-bit code;
* ``din`` changes as ``sclk`` rises, half an SCLK period before the falling edge the DAC takes
  it on, and holds for the half after;
* ``sclk`` is high when ``sync_n`` falls, half a period before its first falling edge; ``sync_n``
  rises half a period after the 24th falling edge and stays high at least the DAC's minimum.

Every output is a register. The half period is the smallest whole number of cycles that keeps
SCLK within the DAC's rate and each half within its minimum (4 cycles at 200 MHz: 25 MHz).
"""

import math

from amaranth import Cat, Const, Module, Mux, Signal, signed
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from spec.facts import VCXO_DAC

from .clock_trim import TRIM_BITS

__all__ = ["TrimDac", "half_period_cycles", "gap_halves"]

_FRAME = int(VCXO_DAC["frame_bits"].value)
_CODE = int(VCXO_DAC["code_bits"].value)


def half_period_cycles(clk_hz):
    """Cycles of ``clk_hz`` in half an SCLK period."""
    need = max(1 / (2 * VCXO_DAC["sclk_max"].value), VCXO_DAC["t_sclk_half_min"].value,
               VCXO_DAC["t_sync_to_sclk_fall"].value, VCXO_DAC["t_data_setup"].value, VCXO_DAC["t_data_hold"].value)
    return max(1, math.ceil(need * clk_hz - 1e-9))


def gap_halves(clk_hz):
    """Half periods ``sync_n`` stays high between two writes."""
    return max(1, math.ceil(VCXO_DAC["t_sync_high_min"].value * clk_hz / half_period_cycles(clk_hz) - 1e-9))


class TrimDac(wiring.Component):
    """The trim word, written to the VCXO's DAC again and again (domain ``sync``).

    Parameters
    ----------
    clk_hz : float
        The domain's clock.

    Members
    -------
    trim : In(signed(16))
        The clock loop's trim word (0: the VCXO's nominal frequency).
    sclk, din, sync_n : Out(1)
        The DAC's serial clock, data and frame sync (registered).
    """
    trim: In(signed(TRIM_BITS))
    sclk: Out(1, init=1)
    din: Out(1)
    sync_n: Out(1, init=1)

    def __init__(self, clk_hz):
        assert TRIM_BITS == _CODE
        self._half, self._gap = half_period_cycles(clk_hz), gap_halves(clk_hz)
        super().__init__()

    def elaborate(self, platform):
        m = Module()
        half, gap = self._half, self._gap
        steps = gap + 2 * _FRAME           # half periods of a write and the gap after it

        tick = Signal()                    # the last cycle of a half period
        count = Signal(range(half))
        m.d.comb += tick.eq(count == half - 1)
        m.d.sync += count.eq(Mux(tick, 0, count + 1))
        step = Signal(range(steps))        # the half period now: the gap, then two a bit
        shift = Signal(_FRAME)

        with m.If(tick):
            m.d.sync += step.eq(step + 1)
            with m.If(step == gap - 1):
                # the word is taken as the write begins: power-down 00, the code offset binary
                frame = Cat(self.trim[:-1], ~self.trim[-1], Const(0, _FRAME - _CODE))
                m.d.sync += [shift.eq(frame), self.din.eq(frame[-1]), self.sync_n.eq(0)]
            with m.Elif(step == steps - 1):
                m.d.sync += [step.eq(0), self.sync_n.eq(1), self.sclk.eq(1)]
            with m.Elif(step >= gap):
                # odd halves (from the gap) fall, taking the bit; even ones rise with the next
                with m.If(step[0] == (gap & 1)):
                    m.d.sync += [self.sclk.eq(0), shift.eq(shift << 1)]
                with m.Else():
                    m.d.sync += [self.sclk.eq(1), self.din.eq(shift[-1])]
        return m
