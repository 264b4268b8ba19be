"""Countdown timers with short carry chains: "has the time come?" as registered flags.

A timer is loaded with ``value`` at cycle ``c``: its time is ``T = c + value - lag``, ``lag``
being a constant of the timer (a load that comes ``lag`` cycles after the cycle its time counts
from, at the end of a pipeline). From then on it says, each cycle ``t`` (as registered flags, no
arithmetic behind them):

* ``done``: ``t >= T``;
* ``late``: ``t > T + slack``, ``slack`` (at most ``lag``) a constant of the timer;
* ``within[k]``: ``T - t < k`` for each constant ``k`` the timer is built with;
* ``ends``: ``t == T + lag``, the count's last cycle: a timer of the same ``lag`` loaded with
  ``v`` on that cycle has its time exactly ``v`` after this one's (timers chain).

The count is held as ``r = max(T - t + 1 + lag, 0)`` in limbs of at most 16 bits, each
decremented when every limb below it is zero (a registered flag per limb), so no carry chain is
longer than 16 bits and every flag is one small comparison of the limb below away from its
register. Values up to ``2**width - 1``; a load of ``lag`` or less is already ``done`` the next
cycle (and late once ``t > T + slack``).
"""

from amaranth import Cat, Const, Module, Signal, Value
from amaranth.lib import data, wiring
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
    flags : str
        Where a load's flags (the comparisons of the value loaded) come from: ``"value"``,
        worked out from ``value`` as it is loaded; ``"settled"``, worked out the cycle before
        (``value`` must hold still for a cycle before a load: a register setting, say);
        ``"given"``, from ``load_flags`` (:meth:`flags_of` a value, registered by the one who
        loads it).

    Members
    -------
    load : In(1)
        Load ``value`` this cycle (``T`` = this cycle + ``value - lag``).
    value : In(width)
    load_flags : In(:meth:`flags_layout`)
        With ``flags="given"``: :meth:`flags_of` ``value``.
    done, late : Out(1)
        The time has come; it has passed.
    within : Out(len(within))
        Bit ``i``: the time comes in fewer than ``within[i]`` cycles (or has come).
    ends : Out(1)
        ``t == T + lag``.
    """

    def __init__(self, width, *, within=(), lag=0, slack=0, flags="value"):
        assert 0 <= slack <= lag
        assert all(0 < k and k + lag + 1 < (1 << LIMB_BITS) - 1 for k in within)
        assert flags in ("value", "settled", "given")
        self._width, self._within, self._lag, self._slack, self._flags = width, tuple(within), lag, slack, flags
        self._bounds = [(lo, min(lo + LIMB_BITS, width)) for lo in range(0, width, LIMB_BITS)]
        members = {
            "load": In(1),
            "value": In(width),
            "done": Out(1, init=1),
            "late": Out(1, init=1),
            "within": Out(max(1, len(within)), init=(1 << max(1, len(within))) - 1),
            "ends": Out(1),
        }
        if flags == "given":
            members["load_flags"] = In(self.flags_layout())
        super().__init__(members)

    def flags_layout(self):
        """The flags a load of a value sets: each limb's zero, ``done``, ``late``, ``within``,
        ``ends``."""
        return data.StructLayout({"zero": len(self._bounds), "done": 1, "late": 1,
                                  "within": max(1, len(self._within)), "ends": 1})

    def flags_of(self, value):
        """The flags of a load of ``value`` (a value-castable; an expression to register)."""
        v = Value.cast(value)
        v_upper_zero = (v[self._bounds[0][1]:] == 0) if len(self._bounds) > 1 else Const(1)
        v_low = v[:self._bounds[0][1]]
        lag, late_at = self._lag, self._lag - self._slack
        within = [v_upper_zero & (v_low <= k + lag) for k in self._within] or [Const(1)]
        return Cat(Cat(v[lo:hi] == 0 for lo, hi in self._bounds), v_upper_zero & (v_low <= 1 + lag),
                   v_upper_zero & (v_low <= late_at), Cat(*within), v_upper_zero & (v_low == 1))

    def flags_registered(self, m, value, name):
        """:meth:`flags_of` ``value`` in two registered stages (each limb's comparisons, then
        the whole): right two cycles after ``value`` last changed."""
        v = Value.cast(value)
        low_end = self._bounds[0][1]
        v_low = v[:low_end]
        lag, late_at = self._lag, self._lag - self._slack
        zero = Signal(len(self._bounds), name=f"{name}_zero")
        low = Signal(3 + len(self._within), name=f"{name}_low")
        m.d.sync += [zero.eq(Cat(v[lo:hi] == 0 for lo, hi in self._bounds)),
                     low.eq(Cat(v_low <= 1 + lag, v_low <= late_at, v_low == 1,
                                *(v_low <= k + lag for k in self._within)))]
        upper_zero = zero[1:].all() if len(self._bounds) > 1 else Const(1)
        flags = Signal(self.flags_layout(), name=name)
        within = [upper_zero & low[3 + i] for i in range(len(self._within))] or [Const(1)]
        m.d.sync += flags.eq(Cat(zero, upper_zero & low[0], upper_zero & low[1], Cat(*within), upper_zero & low[2]))
        return flags

    def elaborate(self, platform):
        m = Module()
        bounds = self._bounds
        limbs = [Signal(hi - lo, name=f"r{i}") for i, (lo, hi) in enumerate(bounds)]
        zero = [Signal(name=f"zero{i}", init=1) for i in range(len(limbs))]

        # r = T - t + 1, held in limbs; limb i borrows when every limb below it is zero
        borrow = [Cat(zero[:i]).all() if i else Const(1) for i in range(len(limbs))]
        counting = Signal()                    # r is not 0: some limb is not zero (registered)
        upper_zero = Cat(zero[1:]).all() if len(limbs) > 1 else Const(1)
        low = limbs[0]
        v = self.value
        lag, late_at = self._lag, self._lag - self._slack
        if self._flags == "given":
            flags = self.load_flags
        else:
            flags = Signal(self.flags_layout())
            if self._flags == "settled":
                m.d.sync += flags.eq(self.flags_of(v))
            else:
                m.d.comb += flags.eq(self.flags_of(v))
        with m.If(self.load):
            # the next cycle's count is the value: done at r <= 1 + lag, late at r <= lag - slack
            for i, ((lo, hi), limb, z) in enumerate(zip(bounds, limbs, zero, strict=True)):
                m.d.sync += [limb.eq(v[lo:hi]), z.eq(flags.zero[i])]
            m.d.sync += [self.done.eq(flags.done), self.late.eq(flags.late), self.ends.eq(flags.ends),
                         counting.eq(~flags.zero.all())]
            for i in range(len(self._within)):
                m.d.sync += self.within[i].eq(flags.within[i])
        with m.Elif(counting):
            # r - 1: each borrowing limb steps down and is zero next if it was one
            for limb, z, b in zip(limbs, zero, borrow, strict=True):
                with m.If(b):
                    m.d.sync += [limb.eq(limb - 1), z.eq(limb == 1)]
            # the flags of r - 1, from r: r - 1 <= x when r <= x + 1
            # (r - 1 is 0 when r is 1: the low limb 1, the upper ones zero, none of them borrowing)
            m.d.sync += [self.done.eq(upper_zero & (low <= 2 + lag)),
                         self.late.eq(upper_zero & (low <= late_at + 1)),
                         self.ends.eq(upper_zero & (low == 2)),
                         counting.eq(~(upper_zero & (low == 1)))]
            for i, k in enumerate(self._within):
                m.d.sync += self.within[i].eq(upper_zero & (low <= k + 1 + lag))
        with m.Else():
            m.d.sync += self.ends.eq(0)
        return m
