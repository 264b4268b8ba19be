"""Link bring-up top for the Spartan-6 build: clocks, the serialiser, and DIN_A/DCLK on LVDS DDR.

What it does on the board: a ramp image is sliced by the bit-plane serialiser and its plane
words are shifted out on DIN_A(15:0) (both DCLK edges, through ODDR2) with DCLK_A forwarded, so
the adapter link can be checked with a scope or logic analyser. The trigger input is
synchronised and echoed on sync out. This is the top the build flow proves itself on; the
projector's platform top composes the full core instead.
"""

from amaranth import Elaboratable, Module, Mux, Signal
from amaranth.lib import io
from amaranth.lib.cdc import FFSynchronizer
from amaranth.lib.fifo import AsyncFIFO

from gateware.bitplane import Serialiser
from gateware.dlpc410 import beat
from gateware.platform.clocks import Spartan6Clocks
from gateware.platform.pins import Dlpc410Pins, TriggerPins
from spec.facts import DMDS

__all__ = ["BringupTop"]


class BringupTop(Elaboratable):
    def elaborate(self, platform):
        m = Module()
        clk100 = platform.request("clk100", dir="-")
        rst = platform.request("rst", dir="-")
        m.submodules.clk_buf = clk_buf = io.Buffer("i", clk100)
        m.submodules.rst_buf = rst_buf = io.Buffer("i", rst)
        # the link at DCLK 200 MHz: one beat a cycle through ODDR2s
        m.domains += Spartan6Clocks.domains(200e6)
        m.submodules.clocks = Spartan6Clocks(clk_buf.i, rst_buf.i, 200e6)

        dmd = DMDS["dlp7000"]
        serialiser = Serialiser(dmd, lanes=8)
        m.submodules.serialiser = serialiser

        # A ramp: pixel value = column, rows in order.
        column = Signal(range(dmd.columns))
        row = Signal(range(dmd.rows))
        m.d.comb += serialiser.pixels.valid.eq(1)
        for j in range(8):
            m.d.comb += serialiser.pixels.payload.pixels[j].eq(column + j)
        m.d.comb += [
            serialiser.pixels.payload.column.eq(column),
            serialiser.pixels.payload.row.eq(row),
            serialiser.rows.ready.eq(1),
        ]
        with m.If(serialiser.pixels.ready):
            m.d.sync += column.eq(column + 8)
            with m.If(column == dmd.columns - 8):
                m.d.sync += row.eq(Mux(row == dmd.rows - 1, 0, row + 1))

        # Plane words cross into DCLK's domain through an async FIFO.
        m.submodules.words_cdc = fifo = AsyncFIFO(width=64, depth=16, w_domain="sync", r_domain="dmd")
        into, out = fifo.w_stream, fifo.r_stream
        m.d.comb += [
            into.payload.eq(serialiser.words.payload.data),
            into.valid.eq(serialiser.words.valid),
            serialiser.words.ready.eq(into.ready),
            out.ready.eq(1),
        ]
        word_dmd = Signal(64)
        with m.If(out.valid):
            m.d.dmd += word_dmd.eq(out.payload)

        m.submodules.dlpc410 = dlpc = Dlpc410Pins()
        lanes = beat.word_to_lanes(word_dmd)
        m.d.comb += [
            dlpc.bus.din_a[0].eq(lanes[("A", "rise")]),
            dlpc.bus.din_a[1].eq(lanes[("A", "fall")]),
            dlpc.bus.dvalid.eq(0b11),
        ]

        m.submodules.trigger = trigger = TriggerPins()
        trigger_dmd = Signal()
        m.submodules.trigger_sync = FFSynchronizer(trigger.trigger, trigger_dmd, o_domain="dmd")
        m.d.comb += trigger.sync.eq(trigger_dmd)
        return m

