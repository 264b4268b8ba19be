"""The Spartan-6 memory controller block's native user port (UG388, "User Interface").

A port is 32, 64 or 128 bits wide (the port configuration chosen in the memory interface
generator) and has three FIFOs on the fabric side: commands (4 deep), write data and read data
(64 words of the port's width each). The MCB takes a command from its FIFO when its arbiter
grants the port; a write command moves ``cmd_bl + 1`` port words out of the write FIFO, so those
words must be in it before the command is given; a read command puts ``cmd_bl + 1`` port words
into the read FIFO, which must have room for them by the time they arrive. Byte addresses are
multiples of the port's word (4, 8 or 16 bytes).

The read FIFO is first-word-fall-through: ``rd_data`` holds the oldest word whenever
``rd_empty`` is low, and ``rd_en`` takes it. A word's bytes are in address order from the low
bits up; ``wr_mask`` bit ``i`` set keeps byte ``i`` of the word's memory unchanged. Every flag is
registered in the port's own clock.

The same signature serves the vendor controller (:mod:`gateware.platform.mcb_instance`) and the
simulation model (:mod:`sim.models.mcb_model`).
"""

from amaranth.lib import enum, wiring
from amaranth.lib.wiring import In, Out

__all__ = ["Instr", "PortSignature", "WIDTHS", "MAX_BURST", "FIFO_DEPTH", "COMMAND_DEPTH"]

WIDTHS = (32, 64, 128)  # port widths the MCB's port configurations offer
MAX_BURST = 64          # port words per command (cmd_bl is 6 bits, words - 1)
FIFO_DEPTH = 64         # port words in the write and read data FIFOs, at every width
COMMAND_DEPTH = 4       # command FIFO


class Instr(enum.Enum, shape=3):
    """``cmd_instr`` codes (UG388 table "Command instruction")."""
    WRITE = 0b000
    READ = 0b001
    WRITE_PRECHARGE = 0b010   # write, then auto-precharge the bank
    READ_PRECHARGE = 0b011    # read, then auto-precharge the bank
    REFRESH = 0b100


class PortSignature(wiring.Signature):
    """One MCB user port of ``width`` bits, seen from the logic that uses it (``Out`` = driven by
    the user).

    Parameters
    ----------
    width : int
        32, 64 or 128.

    Members
    -------
    cmd_en, cmd_instr, cmd_bl, cmd_byte_addr : Out
        Push a command: instruction, burst length in port words minus one (0..63) and a byte
        address that is a multiple of ``word_bytes``.
    cmd_full, cmd_empty : In
        Command FIFO flags; never push while ``cmd_full``.
    wr_en, wr_data, wr_mask : Out(1), Out(width), Out(width // 8)
        Push a write word (mask bit set = byte not written).
    wr_full, wr_empty, wr_count : In
        Write FIFO state (``wr_count`` port words in it).
    wr_underrun, wr_error : In
        The controller found the write FIFO empty during a write command (sticky error).
    rd_en : Out
        Take the word on ``rd_data``.
    rd_data, rd_full, rd_empty, rd_count : In(width), In(1), In(1), In(7)
        Read FIFO (first-word-fall-through).
    rd_overflow, rd_error : In
        Read data arrived while the read FIFO was full, and was lost (sticky error).
    calib_done : In
        The controller has calibrated the memory; no traffic before it.
    """

    def __init__(self, width=64):
        assert width in WIDTHS, f"an MCB port is {', '.join(map(str, WIDTHS))} bits wide, not {width}"
        self.width = width
        super().__init__({
            "cmd_en": Out(1),
            "cmd_instr": Out(Instr),
            "cmd_bl": Out(6),
            "cmd_byte_addr": Out(30),
            "cmd_full": In(1),
            "cmd_empty": In(1),
            "wr_en": Out(1),
            "wr_data": Out(width),
            "wr_mask": Out(width // 8),
            "wr_full": In(1),
            "wr_empty": In(1),
            "wr_count": In(7),
            "wr_underrun": In(1),
            "wr_error": In(1),
            "rd_en": Out(1),
            "rd_data": In(width),
            "rd_full": In(1),
            "rd_empty": In(1),
            "rd_count": In(7),
            "rd_overflow": In(1),
            "rd_error": In(1),
            "calib_done": In(1),
        })

    @property
    def word_bytes(self):
        """Bytes in a port word; byte addresses are multiples of it."""
        return self.width // 8

    def __eq__(self, other):
        return isinstance(other, PortSignature) and other.width == self.width

    def __repr__(self):
        return f"mcb.PortSignature({self.width})"
