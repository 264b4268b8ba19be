"""Clocks of the projector on a Spartan-6: one PLL from the board oscillator.

=========  ==========  ===========================================
domain     frequency   use
=========  ==========  ===========================================
sync       125 MHz     protocol, serialiser, DDR2 writer, status
dmd        200 MHz     plane reader, sequencer, DIN/DVALID output registers
dclk       200 MHz     DCLK forwarding only: 90 degrees after ``dmd``, so that each
                       DCLK edge falls in the middle of a DIN bit
gmii_tx    125 MHz     MAC transmit (forwarded to GTX_CLK)
=========  ==========  ===========================================

``gmii_rx`` comes from the PHY's RX_CLK and is made by the platform top. Each domain's reset is
held until the PLL locks and released synchronously (:class:`amaranth.lib.cdc.ResetSynchronizer`).
The domains belong to the top (``m.domains += Spartan6Clocks.domains()``); this block drives them.
"""

from amaranth import ClockDomain, ClockSignal, Elaboratable, Instance, Module, Signal
from amaranth.lib.cdc import ResetSynchronizer

__all__ = ["Spartan6Clocks", "PLL_PLAN"]

#: VCO = 100 MHz x 10 = 1 GHz (inside Spartan-6 -3's 400-1080 MHz range); outputs divide it.
PLL_PLAN = {
    "input_mhz": 100.0,
    "mult": 10,
    "outputs": {"sync": 8, "dmd": 5, "dclk": 5, "gmii_tx": 8},
    "phases": {"dclk": 90.0},
}


class Spartan6Clocks(Elaboratable):
    """PLL_BASE + BUFGs for ``sync``, ``dmd`` and ``gmii_tx``.

    Parameters
    ----------
    clk_in : Signal
        The board oscillator (100 MHz on the Atlys).
    rst_in : Signal
        Board reset button (active high).
    """

    def __init__(self, clk_in, rst_in):
        self.clk_in = clk_in
        self.rst_in = rst_in
        self.locked = Signal()

    @staticmethod
    def domains():
        """The clock domains this block drives; the top that owns them adds them."""
        return [ClockDomain(name) for name in PLL_PLAN["outputs"]]

    @staticmethod
    def frequencies():
        """``{domain: Hz}`` of the plan."""
        vco = PLL_PLAN["input_mhz"] * PLL_PLAN["mult"]
        return {name: vco / div * 1e6 for name, div in PLL_PLAN["outputs"].items()}

    def elaborate(self, platform):
        m = Module()
        feedback = Signal()
        names = list(PLL_PLAN["outputs"])
        raw = {name: Signal(name=f"pll_{name}") for name in names}
        params = dict(
            p_BANDWIDTH="OPTIMIZED", p_CLK_FEEDBACK="CLKFBOUT", p_COMPENSATION="INTERNAL",
            p_CLKIN_PERIOD=1000 / PLL_PLAN["input_mhz"], p_DIVCLK_DIVIDE=1,
            p_CLKFBOUT_MULT=PLL_PLAN["mult"], p_CLKFBOUT_PHASE=0.0,
            i_CLKIN=self.clk_in, i_RST=self.rst_in, i_CLKFBIN=feedback,
            o_CLKFBOUT=feedback, o_LOCKED=self.locked,
        )
        for i, name in enumerate(names):
            params[f"p_CLKOUT{i}_DIVIDE"] = PLL_PLAN["outputs"][name]
            params[f"p_CLKOUT{i}_PHASE"] = PLL_PLAN["phases"].get(name, 0.0)
            params[f"p_CLKOUT{i}_DUTY_CYCLE"] = 0.5
            params[f"o_CLKOUT{i}"] = raw[name]
        m.submodules.pll = Instance("PLL_BASE", **params)

        for name in names:
            m.submodules[f"bufg_{name}"] = Instance("BUFG", i_I=raw[name], o_O=ClockSignal(name))
            m.submodules[f"rst_{name}"] = ResetSynchronizer(~self.locked, domain=name)
        return m
