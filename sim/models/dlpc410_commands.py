"""Decode the DLPC410 interface into a command list, and the light each pixel receives.

A deliberately small reader of the pins, for comparing the sequencer with the schedule model
cycle for cycle (:mod:`gateware.dlpc410.schedule` speaks the same command tuples) and for
measuring the light of a PWM frame. Rule checking is the DLPC410 model's business.

Commands are ``(cycle, kind, arg)``: ``("row", row)``, ``("clear", block)``, ``("noop", None)``
and ``("pulse", blocks)``, ``cycle`` being the first cycle of the row cycle.
"""

import numpy as np

from gateware.dlpc410.beat import lanes_to_word
from gateware.dlpc410.facts import BlockMode, RowMode

__all__ = ["CommandDecoder", "pulse_blocks"]


def pulse_blocks(dmd, blkmd, blkad, rst2blkz):
    """Blocks a clocking-pulse command covers (facts: block commands)."""
    if blkmd == BlockMode.RESET:
        return (blkad,)
    if blkad & 0b1000:
        return tuple(range(dmd.blocks))
    if rst2blkz:
        q = (blkad >> 1) & 3
        return tuple(b for b in range(4 * q, 4 * q + 4) if b < dmd.blocks)
    return tuple(b for b in (2 * blkad, 2 * blkad + 1) if b < dmd.blocks)


class CommandDecoder:
    """Feed :meth:`step` once per cycle with the pins; read :attr:`commands` and :attr:`light`.

    Tracks the DMD memory and the mirror state (0/1 arrays) and integrates each pixel's on-time
    in cycles between clocking pulses (:attr:`light`, reset by :meth:`take_light`).
    """

    def __init__(self, dmd):
        self.dmd = dmd
        self.commands = []
        self.memory = np.zeros((dmd.rows, dmd.columns), dtype=np.uint8)
        self.mirrors = np.zeros_like(self.memory)
        self.light = np.zeros(self.memory.shape, dtype=np.int64)
        self.last_pulse = [None] * dmd.blocks
        self._beat = 0
        self._cmd = None
        self._words = []
        self._pointer = 0

    def _rows(self, block):
        return slice(block * self.dmd.rows_per_block, (block + 1) * self.dmd.rows_per_block)

    def step(self, cycle, dvalid, rowmd, rowad, blkmd, blkad, rst2blkz, lanes):
        """``lanes``: {(bus, edge): 16-bit value} as :func:`gateware.dlpc410.beat.lanes_to_word`."""
        R = self.dmd.dclk_per_row
        if not dvalid:
            assert self._beat == 0, f"DVALID fell inside a row cycle at {cycle}"
            return
        if self._beat == 0:
            self._cmd = (cycle, RowMode(rowmd), rowad, BlockMode(blkmd), blkad, rst2blkz)
            self._words = []
            self._block_command(cycle, BlockMode(blkmd), blkad, rst2blkz)
        self._words.append(lanes_to_word(lanes))
        self._beat += 1
        if self._beat == R:
            self._beat = 0
            self._row_command()

    def _block_command(self, cycle, blkmd, blkad, rst2blkz):
        if blkmd == BlockMode.CLEAR:
            self.commands.append((cycle, "clear", blkad))
            self.memory[self._rows(blkad)] = 0
        elif blkmd in (BlockMode.RESET, BlockMode.MULTI):
            blocks = pulse_blocks(self.dmd, blkmd, blkad, rst2blkz)
            self.commands.append((cycle, "pulse", blocks))
            for b in blocks:
                rows = self._rows(b)
                if self.last_pulse[b] is not None:
                    self.light[rows] += self.mirrors[rows].astype(np.int64) * (cycle - self.last_pulse[b])
                self.last_pulse[b] = cycle
                self.mirrors[rows] = self.memory[rows]

    def _row_command(self):
        cycle, rowmd, rowad, blkmd, _blkad, _r2 = self._cmd
        if rowmd == RowMode.NOOP:
            if blkmd == BlockMode.NOOP:
                self.commands.append((cycle, "noop", None))
            return
        row = {RowMode.ADDRESSED: rowad, RowMode.FIRST: 0, RowMode.NEXT: self._pointer + 1}[rowmd]
        self._pointer = row
        self.commands.append((cycle, "row", row))
        words = np.array(self._words, dtype="<u8")
        self.memory[row] = np.unpackbits(words.view(np.uint8), bitorder="little")

    def take_light(self):
        """The light integrated so far (cycles per pixel), and start again from zero."""
        light, self.light = self.light, np.zeros_like(self.light)
        return light
