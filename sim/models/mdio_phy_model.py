"""A PHY's management interface (IEEE 802.3 clause 22), as the station management sees it.

``step(mdc, mdio_o, mdio_oe)`` once per cycle of the management block's clock returns the level
on the MDIO pin (pulled up when nobody drives it). The model decodes frames on MDC rising edges,
answers reads of its registers, and records every frame; it raises :class:`MdioError` on a
frame that breaks the clause: short preamble, wrong start, both sides driving.
"""

__all__ = ["MdioPhy", "MdioError"]


class MdioError(AssertionError):
    pass


class MdioPhy:
    def __init__(self, address, registers):
        self.address = address
        self.registers = dict(registers)
        self.reads = []            # (phy address, register) of each read answered
        self._mdc = 0
        self._ones = 0             # preamble ones seen
        self._bits = None          # bits of the frame after the preamble, or None between frames
        self._drive = None         # bit the PHY drives now (None: released)
        self._answer = []

    def step(self, mdc, mdio_o, mdio_oe):
        if mdio_oe and self._drive is not None:
            raise MdioError("station and PHY drive MDIO at once")
        level = mdio_o if mdio_oe else (1 if self._drive is None else self._drive)
        if mdc and not self._mdc:
            self._rising(level)
        self._mdc = mdc
        return level

    def _rising(self, level):
        if self._answer:
            self._drive = self._answer.pop(0)
            return
        self._drive = None
        if self._bits is None:
            if level:
                self._ones += 1
            elif self._ones >= 32:
                self._bits = [0]
            elif self._ones:
                raise MdioError(f"preamble of {self._ones} ones, 32 needed")
            return
        self._bits.append(level)
        if len(self._bits) == 14:
            self._frame(self._bits)
            self._bits, self._ones = None, 0

    def _frame(self, bits):
        value = int("".join(map(str, bits)), 2)
        start, op, phy, reg = value >> 12, (value >> 10) & 3, (value >> 5) & 31, value & 31
        if start != 0b01:
            raise MdioError(f"start field {start:02b}, 01 expected")
        if op == 0b10 and phy == self.address:
            self.reads.append((phy, reg))
            data = self.registers.get(reg, 0)
            # turnaround: released on the first bit, 0 on the second; then 16 bits MSB first
            self._answer = [None, 0] + [(data >> (15 - i)) & 1 for i in range(16)]
            self._drive = self._answer.pop(0)
