"""The AD5662 16-bit DAC's serial interface, written from its data sheet's description: the
oracle of the VCXO DAC writer (:mod:`gateware.sync.trim_dac`).

SYNC falling starts a write; each SCLK falling edge while SYNC is low takes DIN into a 24-bit
shift register, most significant first; on the 24th the output takes DB15..DB0 (straight
binary) and DB17..DB16 set the power-down mode. SYNC rising before the 24th falling edge
abandons the write. Every edge is checked against the interface's timing: the SCLK cycle and
its high and low times, SYNC to the first falling edge, DIN's setup and hold around each falling
edge, and SYNC's high time between writes. The numbers are the data sheet's (2.7 V to 5.5 V),
written here again, not taken from the facts table the gateware uses.
"""

__all__ = ["Ad5662", "TimingError", "TrimWrites", "trim_scenario"]

#: Minimum times, ns: SCLK cycle (t1), high (t2), low (t3), SYNC to SCLK falling (t4), data
#: setup (t5), data hold (t6), SYNC high (t8).
T1, T2, T3, T4, T5, T6, T8 = 33, 13, 13, 13, 5, 4.5, 33


class TimingError(AssertionError):
    """A line changed too soon for the DAC."""


class Ad5662:
    """Feed :meth:`sample` the three lines at increasing times (ns); ``codes`` lists the code of
    every completed write, ``power_down`` its mode, ``abandoned`` counts writes cut short."""

    def __init__(self):
        self.codes, self.modes, self.abandoned = [], [], 0
        self._last = None                  # (t, sclk, din, sync_n) of the previous sample
        self._bits = None                  # the write's bits so far (None: SYNC high)
        self._sync_fell = self._sync_rose = None
        self._sclk_fell = self._sclk_rose = None
        self._din_changed = None

    @property
    def code(self):
        return self.codes[-1] if self.codes else None

    def sample(self, t, sclk, din, sync_n):
        if self._last is None:
            self._last = (t, sclk, din, sync_n)
            return
        _, sclk0, din0, sync0 = self._last
        self._last = (t, sclk, din, sync_n)
        if din != din0:
            self._din_changed = t
            if self._sclk_fell is not None and self._bits is not None and t - self._sclk_fell < T6:
                raise TimingError(f"{t} ns: DIN held {t - self._sclk_fell} ns after SCLK fell (t6 {T6})")
        if sync0 and not sync_n:
            if self._sync_rose is not None and t - self._sync_rose < T8:
                raise TimingError(f"{t} ns: SYNC high {t - self._sync_rose} ns (t8 {T8})")
            self._sync_fell, self._bits = t, []
        if not sync0 and sync_n:
            self._sync_rose = t
            if self._bits is not None and len(self._bits) < 24:
                self.abandoned += 1
            self._bits = None
        if sclk0 and not sclk:
            self._falling(t, din)
        if sclk and not sclk0:
            if self._sclk_fell is not None and t - self._sclk_fell < T3:
                raise TimingError(f"{t} ns: SCLK low {t - self._sclk_fell} ns (t3 {T3})")
            self._sclk_rose = t

    def _falling(self, t, din):
        if self._sclk_rose is not None and t - self._sclk_rose < T2:
            raise TimingError(f"{t} ns: SCLK high {t - self._sclk_rose} ns (t2 {T2})")
        if self._sclk_fell is not None and t - self._sclk_fell < T1:
            raise TimingError(f"{t} ns: SCLK cycle {t - self._sclk_fell} ns (t1 {T1})")
        self._sclk_fell = t
        if self._bits is None:
            return
        if not self._bits and t - self._sync_fell < T4:
            raise TimingError(f"{t} ns: first SCLK falling edge {t - self._sync_fell} ns after SYNC (t4 {T4})")
        if self._din_changed is not None and t - self._din_changed < T5:
            raise TimingError(f"{t} ns: DIN set up {t - self._din_changed} ns before SCLK fell (t5 {T5})")
        self._bits.append(din)
        if len(self._bits) == 24:
            word = 0
            for bit in self._bits:
                word = word << 1 | bit
            self.codes.append(word & 0xFFFF)
            self.modes.append(word >> 16 & 3)
            self._bits = None              # further edges before SYNC rises start nothing new


def trim_scenario(rng, cycles):
    """Trim words to present: ``{cycle: word}`` (signed 16-bit), changing now and then, some
    changes a cycle apart (during a write), the extremes among them."""
    changes, t = {0: 0}, 0
    extremes = [-(1 << 15), (1 << 15) - 1, -1, 1]
    while t < cycles:
        t += rng.choice([1, 2, 37, 150, 400, 1000])
        changes[t] = extremes.pop() if extremes and rng.random() < 0.3 else rng.randint(-(1 << 15), (1 << 15) - 1)
    return changes


class TrimWrites:
    """Watches a trim word writer's lines through :class:`Ad5662`, a sample a clock cycle
    (``period_ns``): every write must carry the trim word as it was presented on the clock edge
    SYNC fell on (offset binary), in power-down mode 0, and none may be abandoned."""

    def __init__(self, period_ns):
        self.dac, self.period_ns = Ad5662(), period_ns
        self.expected, self._sync = [], 1

    def cycle(self, t, trim, sclk, din, sync_n):
        """The lines after clock edge ``t``; ``trim``: the word presented on that edge."""
        if self._sync and not sync_n:
            self.expected.append((trim & 0xFFFF) ^ 0x8000)
        self._sync = sync_n
        self.dac.sample(t * self.period_ns, sclk, din, sync_n)

    def check(self):
        done = len(self.dac.codes)
        assert done > 0, "no write completed"
        assert self.dac.codes == self.expected[:done], (self.dac.codes[:4], self.expected[:4])
        assert set(self.dac.modes) == {0} and self.dac.abandoned == 0
        return done
