"""A minimal driver of the DLPC410 interface, for tests: legal cycles built by hand.

:class:`Driver` appends the per-cycle signal dicts of :meth:`sim.models.dlpc410_model.Dlpc410.step`
(and :class:`Idle` runs of DVALID-low cycles) to :attr:`Driver.items` and counts cycles, so a
test knows the cycle of every command it issued without asking the model. It applies no timing
rule itself: legal or not is the caller's choice, which is how rule breaks are injected.
"""

from dataclasses import dataclass, field

import numpy as np

from gateware.dlpc410.beat import PINS_PER_BUS, word_to_lanes
from spec.facts import TIMING, BlockMode, RowMode

__all__ = ["Idle", "Driver", "row_words", "expand"]


@dataclass
class Idle:
    """``count`` cycles of ``signals`` with DVALID low."""
    count: int
    signals: dict = field(default_factory=lambda: {"arstz": 1})


def row_words(bits):
    """A row of 0/1 pixels -> its 64-bit words (word bit ``i`` = column ``64 w + i``)."""
    bits = np.asarray(bits, np.uint8).reshape(-1, 64)
    return [int(w) for w in np.packbits(bits, axis=1, bitorder="little").view("<u8").ravel()]


def _pair(lanes, bus):
    return lanes[(bus, "rise")] | (lanes[(bus, "fall")] << PINS_PER_BUS)


#: The training pattern's bit on each of its four DDR edges (facts: ``0100``, edge 0 first).
_TRAINING = tuple(int(TIMING["training_pattern"].value) >> (3 - k) & 1 for k in range(4))


def beat_pins(words, buses, beat=0):
    """The words of one beat -> ``{"din_a": packed edge pair, ...}`` (the second word of a
    four-bus DMD on C/D), placed at the ``beat``-th DCLK cycle's edges of a ``dmd`` cycle."""
    pins = {}
    for i, word in enumerate(words):
        lanes = word_to_lanes(word)
        first, second = buses[2 * i], buses[2 * i + 1]
        pins[f"din_{first}"] = _pair(lanes, "A") << (2 * PINS_PER_BUS * beat)
        pins[f"din_{second}"] = _pair(lanes, "B") << (2 * PINS_PER_BUS * beat)
    return pins


def cycle_pins(words, buses, beats):
    """The words of one ``dmd`` cycle of ``beats`` beats -> the packed data pins."""
    per_beat = len(words) // beats
    pins = {f"din_{b}": 0 for b in buses}
    for beat in range(beats):
        for name, value in beat_pins(words[beat * per_beat:(beat + 1) * per_beat], buses, beat).items():
            pins[name] |= value
    return pins


def expand(items):
    """Items -> one dict per cycle (Idle runs unrolled)."""
    for item in items:
        if isinstance(item, dict):
            yield item
        else:
            yield from (dict(item.signals) for _ in range(item.count))


class Driver:
    """Builds a cycle sequence for ``dmd`` at ``beats`` DCLK cycles per cycle; :attr:`cycle`
    is the index of the next cycle."""

    def __init__(self, dmd, beats=1):
        self.dmd = dmd
        self.beats = beats
        self.buses = "abcd"[:dmd.buses]
        self.words_per_cycle = dmd.bits_per_dclk * beats // 64
        self.items = []
        self.cycle = 0

    def _emit(self, signals):
        self.items.append(signals)
        self.cycle += 1

    def hold_reset(self, count):
        """ARSTZ low, training pattern already on the pins (it must precede ARSTZ rising)."""
        self.training(count, arstz=0)

    def training(self, count, *, arstz=1):
        """The training pattern ``0100`` on every data pin and DVALID, edge after edge (its
        phase counted from cycle 0); no commands."""
        edges = 2 * self.beats
        for _ in range(count):
            bits = [_TRAINING[(self.cycle * edges + e) % 4] for e in range(edges)]
            din = sum((0xffff if bit else 0) << (PINS_PER_BUS * e) for e, bit in enumerate(bits))
            dvalid = sum(bit << e for e, bit in enumerate(bits))
            self._emit({"arstz": arstz, "dvalid": dvalid, **{f"din_{b}": din for b in self.buses}})

    def start(self, init_cycles, *, reset_cycles=4, ecp2_cycles=4, after=64):
        """Reset, training through initialisation, then the wait before the first DVALID.
        Returns the cycle ARSTZ rose."""
        self.hold_reset(reset_cycles)
        rise = self.cycle
        self.training(max(rise, ecp2_cycles) + init_cycles - rise)
        self.idle(after)
        return rise

    def idle(self, count):
        """``count`` cycles with DVALID low."""
        if count:
            self.items.append(Idle(count))
            self.cycle += count

    def wait_until(self, cycle):
        """Idle up to ``cycle`` or the next even count of cycles after it (an even gap)."""
        count = max(0, cycle - self.cycle)
        self.idle(count + (count & 1))

    def row(self, rowmd=RowMode.NOOP, *, rowad=0, bits=None, blkmd=BlockMode.NOOP, blkad=0,
            rst2blkz=1, comp_data=0, ns_flip=0, cut=None):
        """One row cycle; ``cut`` ends it after that many cycles (a rule break). Returns the
        cycle it starts on."""
        start = self.cycle
        words = row_words(bits) if bits is not None else [0] * self.dmd.words_per_row
        command = {"arstz": 1, "dvalid": (1 << (2 * self.beats)) - 1, "rowmd": int(RowMode(rowmd).value),
                   "rowad": rowad, "blkmd": int(BlockMode(blkmd).value), "blkad": blkad, "rst2blkz": rst2blkz,
                   "comp_data": comp_data, "ns_flip": ns_flip}
        n = self.words_per_cycle
        for c in range(self.dmd.dclk_per_row // self.beats if cut is None else cut):
            self._emit({**command, **cycle_pins(words[c * n:(c + 1) * n], self.buses, self.beats)})
        return start

    def load(self, plane, rows=None, *, ns_flip=0):
        """Write ``plane`` (rows x columns of 0/1) row by row: the first with ROWMD 11, the rest
        with 01 (pointer order; bottom up with ``ns_flip``), or only ``rows`` with ROWMD 10."""
        plane = np.asarray(plane)
        if rows is None:
            order = range(self.dmd.rows - 1, -1, -1) if ns_flip else range(self.dmd.rows)
            for i, r in enumerate(order):
                self.row(RowMode.FIRST if i == 0 else RowMode.NEXT, bits=plane[r], ns_flip=ns_flip)
        else:
            for r in rows:
                self.row(RowMode.ADDRESSED, rowad=r, bits=plane[r])

    def clear(self, block):
        """Clear ``block``: its row cycle, then the no-op rows a clear occupies. Returns its cycle."""
        start = self.row(blkmd=BlockMode.CLEAR, blkad=block)
        for _ in range(self.dmd.clear_row_cycles - 1):
            self.row()
        return start

    def pulse(self, kind="global", group=0):
        """A mirror clocking pulse: ``single`` (block ``group``), ``dual`` (blocks 2g, 2g+1),
        ``quad`` (4g..4g+3) or ``global``. Returns its cycle."""
        blkmd, blkad, rst2blkz = {
            "single": (BlockMode.RESET, group, 1),
            "dual": (BlockMode.MULTI, group, 0),
            "quad": (BlockMode.MULTI, group << 1, 1),
            "global": (BlockMode.MULTI, 0b1000, 1),
        }[kind]
        return self.row(blkmd=blkmd, blkad=blkad, rst2blkz=rst2blkz)


def play_schedule(driver, dmd, p, result, images, offset):
    """Append the command stream of a :func:`spec.schedule.simulate` ``result`` to
    ``driver``: schedule cycle ``t`` becomes driver cycle ``t + offset`` (asserted, so a gap the
    schedule leaves odd or too short shows here). Each row carries the plane its group's next
    pulse shows (``images[frame index]``, 8-bit; zeros after the group's last pulse); dark pulses
    show cleared blocks."""
    from spec.schedule import groups, pulse_encoding

    grp = groups(dmd, p.reset_mode)
    group_of = {b: g for g, blocks in enumerate(grp) for b in blocks}
    pulses = {g: [(t, fi, e) for t, gg, _kind, fi, e in result.pulses if gg == g] for g in range(len(grp))}
    seen = [0] * len(grp)                       # pulses of each group issued so far
    planes = {}

    def plane(fi, e):
        if (fi, e) not in planes:
            planes[fi, e] = (np.asarray(images[fi]) >> result.shown[fi].stored_plane(e)) & 1
        return planes[fi, e]

    # the no-op rows a 1080p clear occupies come with the clear (Driver.clear)
    for t, kind, arg in result.decoded():
        driver.wait_until(t + offset)
        if kind == "pulse":
            g = group_of[arg[0]]
            blkmd, blkad, rst2blkz = pulse_encoding(dmd, p.reset_mode, g)
            start = driver.row(blkmd=blkmd, blkad=blkad, rst2blkz=rst2blkz)
            seen[g] += 1
        elif kind == "clear":
            start = driver.clear(arg)
        elif kind == "row":
            g = group_of[dmd.block_of_row(arg)]
            # rows loaded after the result's last pulse of the group are never shown: zeros
            bits = None
            if seen[g] < len(pulses[g]):
                _t, fi, e = pulses[g][seen[g]]
                assert e is not None, f"row {arg} loaded for a dark pulse"
                bits = plane(fi, e)[arg]
            start = driver.row(RowMode.ADDRESSED, rowad=arg, bits=bits)
        assert start == t + offset, f"{kind} at schedule cycle {t} lands on {start - offset}"
