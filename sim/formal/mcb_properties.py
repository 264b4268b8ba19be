"""The write half of an MCB user port, as a formal environment: what the controller may do, and
the port rules its user must keep.

Commands wait in a four-deep FIFO and each is carried out at a moment the solver chooses (once
its words are in the write FIFO); ``executed`` then shows the burst that reaches the memory. The
flags the user reads (``cmd_full``, ``cmd_empty``, ``wr_empty``, ``wr_count``) are registered,
one cycle late, as the controller's are. The rules of :mod:`gateware.store.mcb` are asserted: no
command while the command FIFO is full, no word beyond the write FIFO, and a write command's
words all pushed before the command.
"""

from amaranth import Array, Module, Signal
from amaranth.asserts import AnySeq
from amaranth.hdl import Assert
from amaranth.lib import data, wiring
from amaranth.lib.wiring import In, Out

from gateware.store import mcb

__all__ = ["WritePortEnvelope", "Burst"]


class Burst(data.Struct):
    """A write command: ``words`` 64-bit words from byte address ``addr``."""
    addr: 30
    words: 7


class WritePortEnvelope(wiring.Component):
    """A free but lawful MCB write port (``sync``).

    Members
    -------
    port : In(mcb.PortSignature())
        The user's port (the writer's ``mcb``).
    executed : Out(Burst), executing : Out(1)
        The command the controller carries out this cycle.
    """

    port: In(mcb.PortSignature())
    executed: Out(Burst)
    executing: Out(1)

    def elaborate(self, platform):
        m = Module()
        port = self.port
        queue = Array(Signal(Burst, name=f"cmd{i}") for i in range(mcb.COMMAND_DEPTH))
        count = Signal(range(mcb.COMMAND_DEPTH + 1))
        words = Signal(range(mcb.FIFO_DEPTH + 1))        # in the write FIFO
        claimed = Signal(range(mcb.FIFO_DEPTH * mcb.COMMAND_DEPTH + 1))  # by queued commands
        head = queue[0]

        # the controller takes the oldest command when it pleases, its words being there
        m.d.comb += [
            self.executing.eq(AnySeq(1) & (count != 0) & (words >= head.words)),
            self.executed.eq(head),
        ]
        push = port.cmd_en & (port.cmd_instr == mcb.Instr.WRITE)
        burst = Signal(Burst)
        m.d.comb += [burst.addr.eq(port.cmd_byte_addr), burst.words.eq(port.cmd_bl + 1)]

        m.d.comb += [
            Assert(~port.cmd_en | (count != mcb.COMMAND_DEPTH), "command while the command FIFO is full"),
            Assert(~port.cmd_en | (port.cmd_instr == mcb.Instr.WRITE), "a command other than WRITE"),
            Assert(~port.wr_en | (words != mcb.FIFO_DEPTH) | self.executing, "write FIFO overflow"),
            Assert(~push | (words - claimed >= burst.words), "a write command before its words"),
            Assert(port.cmd_byte_addr[:3] == 0, "a byte address off a word"),
        ]

        # the FIFOs
        out_words = Signal.like(words)
        with m.If(self.executing):
            for i in range(mcb.COMMAND_DEPTH - 1):
                m.d.sync += queue[i].eq(queue[i + 1])
            m.d.comb += out_words.eq(head.words)
        with m.If(push):
            m.d.sync += queue[count - self.executing].eq(burst)
        m.d.sync += [
            count.eq(count + push - self.executing),
            words.eq(words + port.wr_en - out_words),
            claimed.eq(claimed + push * burst.words - out_words),
        ]

        # the flags, one cycle late
        m.d.sync += [
            port.cmd_full.eq(count == mcb.COMMAND_DEPTH),
            port.cmd_empty.eq(count == 0),
            port.wr_empty.eq(words == 0),
            port.wr_count.eq(words),
        ]
        m.d.comb += port.calib_done.eq(1)
        return m
