"""Countdown timers with short carry chains: "has the time come?" as registered flags.

A timer is loaded with ``value`` at cycle ``c``: its time is ``T = c + value - lag``, ``lag``
being a constant of the timer (a load that comes ``lag`` cycles after the cycle its time counts
from, at the end of a pipeline). From then on it says, each cycle ``t`` (as registered flags, no
arithmetic behind them):

* ``done``: ``t >= T``;
* ``late``: ``t > T + slack``, ``slack`` (at most ``lag``) a constant of the timer;
* ``within[k]``: ``T - t < k`` for each constant ``k`` the timer is built with.

The count is held as ``r = max(T - t + 1 + lag, 0)`` in limbs of at most 16 bits, each
decremented when every limb below it is zero (a registered flag per limb), so no carry chain is
longer than 16 bits and every flag is one small comparison of the limb below away from its
register. Values up to ``2**width - 1``; a load of ``lag`` or less is already ``done`` the next
cycle (and late once ``t > T + slack``).
"""

from amaranth import Cat, Const, Module, Signal
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

__all__ = ["Countdown", "LIMB_BITS"]

#: The longest carry chain a limb makes.
LIMB_BITS = 16


class Countdown(wiring.Component):
    """One timer.

    Parameters
    ----------
    width : int
        Bits of the longest value.
    within : tuple of int
        Distances ``k`` (each below ``2**LIMB_BITS - 1 - lag``) for the ``within`` flags.
    lag : int
        Cycles between the cycle a time counts from and its load.
    slack : int
        ``late`` is ``t > T + slack`` (at most ``lag``).

    Members
    -------
    load : In(1)
        Load ``value`` this cycle (``T`` = this cycle + ``value - lag``).
    value : In(width)
    done, late : Out(1)
        The time has come; it has passed.
    within : Out(len(within))
        Bit ``i``: the time comes in fewer than ``within[i]`` cycles (or has come).
    """

    def __init__(self, width, *, within=(), lag=0, slack=0):
        assert 0 <= slack <= lag
        assert all(0 < k and k + lag + 1 < (1 << LIMB_BITS) - 1 for k in within)
        self._width, self._within, self._lag, self._slack = width, tuple(within), lag, slack
        super().__init__({
            "load": In(1),
            "value": In(width),
            "done": Out(1, init=1),
            "late": Out(1, init=1),
            "within": Out(max(1, len(within)), init=(1 << max(1, len(within))) - 1),
        })

    def elaborate(self, platform):
        m = Module()
        width = self._width
        bounds = [(lo, min(lo + LIMB_BITS, width)) for lo in range(0, width, LIMB_BITS)]
        limbs = [Signal(hi - lo, name=f"r{i}") for i, (lo, hi) in enumerate(bounds)]
        zero = [Signal(name=f"zero{i}", init=1) for i in range(len(limbs))]

        # r = T - t + 1, held in limbs; limb i borrows when every limb below it is zero
        borrow = [Cat(zero[:i]).all() if i else Const(1) for i in range(len(limbs))]
        counting = ~Cat(zero).all()
        upper_zero = Cat(zero[1:]).all() if len(limbs) > 1 else Const(1)
        low = limbs[0]
        v = self.value
        v_upper_zero = (v[bounds[0][1]:] == 0) if len(limbs) > 1 else Const(1)
        v_low = v[:bounds[0][1]]
        lag, late_at = self._lag, self._lag - self._slack
        with m.If(self.load):
            # the next cycle's count is the value: done at r <= 1 + lag, late at r <= lag - slack
            for (lo, hi), limb, z in zip(bounds, limbs, zero, strict=True):
                m.d.sync += [limb.eq(v[lo:hi]), z.eq(v[lo:hi] == 0)]
            m.d.sync += [self.done.eq(v_upper_zero & (v_low <= 1 + lag)),
                         self.late.eq(v_upper_zero & (v_low <= late_at))]
            for i, k in enumerate(self._within):
                m.d.sync += self.within[i].eq(v_upper_zero & (v_low <= k + lag))
        with m.Elif(counting):
            # r - 1: each borrowing limb steps down and is zero next if it was one
            for limb, z, b in zip(limbs, zero, borrow, strict=True):
                with m.If(b):
                    m.d.sync += [limb.eq(limb - 1), z.eq(limb == 1)]
            # the flags of r - 1, from r: r - 1 <= x when r <= x + 1
            m.d.sync += [self.done.eq(upper_zero & (low <= 2 + lag)),
                         self.late.eq(upper_zero & (low <= late_at + 1))]
            for i, k in enumerate(self._within):
                m.d.sync += self.within[i].eq(upper_zero & (low <= k + 1 + lag))
        return m
