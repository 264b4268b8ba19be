"""A 128-bit MCB read port on a 64-bit one.

The Spartan-6 MCB offers a 128-bit user port only as the controller's single port (UG388 port
configurations: two 32-bit bidirectional and four 32-bit unidirectional ports; four 32-bit
bidirectional; one 64-bit and two 32-bit bidirectional; two 64-bit bidirectional; one 128-bit
bidirectional), so the store's 128-bit reader and 64-bit writer cannot each have a port of
their width. The Atlys build takes two 64-bit ports and puts this block between the reader and
its port: at the reader's 200 MHz a 64-bit port moves 1.6 GB/s, the DDR2-800 x16's own peak,
so the narrower port costs the reader no bandwidth.

A read command of ``n`` 128-bit words at a 16-byte aligned address becomes one command of
``2 n`` 64-bit words, or two (64 words, then the rest) when ``n`` > 32; its 64-bit words are
paired, the first in the low bits, and given as 128-bit words through a first-word-fall-through
register. The 64-bit read FIFO is drained one word a cycle whenever the pair register is free
or being taken, so as long as the user takes each word as soon as it is there (as the plane
reader does), neither FIFO can overflow. Only reads (and refreshes) pass: the write half is
closed (``wr_full`` always set).
"""

from amaranth import Cat, Module, Mux, Signal
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from gateware.store import mcb

__all__ = ["ReadWidener"]


class ReadWidener(wiring.Component):
    """A 128-bit read port (``user``) on a 64-bit MCB port (``mcb``), in one clock domain.

    Members
    -------
    user : In(mcb.PortSignature(128))
        The port the reader sees; ``cmd_bl``, ``rd_data`` and ``rd_count`` in 128-bit words.
    mcb : Out(mcb.PortSignature(64))
        The memory controller's port.
    """

    #: 64-bit words per command on the MCB's side at most
    _HALF = mcb.MAX_BURST // 2

    def __init__(self):
        super().__init__({
            "user": In(mcb.PortSignature(128)),
            "mcb": Out(mcb.PortSignature(64)),
        })

    def elaborate(self, platform):
        m = Module()
        user, port = self.user, self.mcb

        # -- commands: the first (or only) part goes out with the user's push, the rest after
        pending = Signal()
        rest_bl = Signal(6)
        rest_address = Signal(30)
        rest_instr = Signal(mcb.Instr)
        words = Signal(8)                           # 64-bit words of the user's command
        m.d.comb += words.eq((user.cmd_bl + 1) * 2)
        m.d.comb += [
            user.cmd_full.eq(port.cmd_full | pending),
            user.cmd_empty.eq(port.cmd_empty & ~pending),
            port.cmd_en.eq(user.cmd_en | (pending & ~port.cmd_full)),
            port.cmd_instr.eq(Mux(pending, rest_instr, user.cmd_instr)),
            port.cmd_bl.eq(Mux(pending, rest_bl, Mux(words > mcb.MAX_BURST, mcb.MAX_BURST, words) - 1)),
            port.cmd_byte_addr.eq(Mux(pending, rest_address, user.cmd_byte_addr)),
        ]
        with m.If(user.cmd_en & (user.cmd_bl >= self._HALF)):
            m.d.sync += [pending.eq(1), rest_bl.eq(words - mcb.MAX_BURST - 1), rest_instr.eq(user.cmd_instr),
                         rest_address.eq(user.cmd_byte_addr + mcb.MAX_BURST * 8)]
        with m.Elif(pending & ~port.cmd_full):
            m.d.sync += pending.eq(0)

        # -- read data: pairs of 64-bit words into a first-word-fall-through register
        low = Signal(64)
        have_low = Signal()
        pair = Signal(128)
        full = Signal()
        take = Signal()
        m.d.comb += [
            take.eq(port.calib_done & ~port.rd_empty & (~have_low | ~full | user.rd_en)),
            port.rd_en.eq(take),
            user.rd_data.eq(pair),
            user.rd_empty.eq(~full),
            user.rd_full.eq(port.rd_full),
            user.rd_count.eq(((port.rd_count + have_low) >> 1) + full),
            user.rd_overflow.eq(port.rd_overflow),
            user.rd_error.eq(port.rd_error),
            user.calib_done.eq(port.calib_done),
        ]
        with m.If(take & ~have_low):
            m.d.sync += [low.eq(port.rd_data), have_low.eq(1)]
        with m.If(take & have_low):
            m.d.sync += [pair.eq(Cat(low, port.rd_data)), full.eq(1), have_low.eq(0)]
        with m.Elif(user.rd_en):
            m.d.sync += full.eq(0)

        # -- no writes through this port
        m.d.comb += [
            port.wr_en.eq(0),
            user.wr_full.eq(1),
            user.wr_empty.eq(1),
            user.wr_underrun.eq(port.wr_underrun),
            user.wr_error.eq(port.wr_error),
        ]
        return m
