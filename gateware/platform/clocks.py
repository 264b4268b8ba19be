"""Clocks of the projector on a Spartan-6: PLLs from the board oscillator (100 MHz on the Atlys,
125 MHz on the SVEC).

=========  ==========  ===========================================
domain     frequency   use
=========  ==========  ===========================================
sync       125 MHz     protocol, serialiser, DDR2 writer, status
gmii_tx    125 MHz     MAC transmit (forwarded to GTX_CLK)
dmd        200 MHz     plane reader, sequencer, the DLPC410 link's parallel side
=========  ==========  ===========================================

The DLPC410 link, by DCLK:

* **400 MHz** (the default; the DLPC410's newer PROM takes nothing else): a second PLL, VCO 800
  MHz (from 125 MHz through a divide by 5 before the phase detector), gives ``dmd`` and two
  800 MHz I/O clocks, each through a BUFPLL (``DIVIDE=4``) that makes the serdes strobe: one
  for the data lanes (DIN, DVALID), one half a bit later (its PLL output at 180 degrees, 625 ps:
  90 degrees of DCLK) for the DCLK lanes (:mod:`.serdes`). ``dmd`` comes from the same PLL, so
  the 4:1 serialisers' parallel and serial clocks are phase-aligned.
* **200 MHz**: one PLL (VCO 1 GHz) gives every domain, and ``dclk``, 90 degrees after ``dmd``,
  for DCLK forwarded through an ODDR2 so that each DCLK edge falls in the middle of a bit.

``gmii_rx`` comes from the PHY's RX_CLK and is made by the platform top. Each domain's reset is
held until its PLL locks and released synchronously (:class:`amaranth.lib.cdc.ResetSynchronizer`).
The domains belong to the top (``m.domains += Spartan6Clocks.domains(dclk_hz)``); this block
drives them.

To check on hardware (nothing here has been through ISE): both PLLs take the oscillator's input
buffer (ISE may want a BUFIO2 or BUFG before the second), and both BUFPLLs must reach the bank of
the DLPC410 adapter's pins.
"""

from fractions import Fraction

from amaranth import ClockDomain, ClockSignal, Elaboratable, Instance, Module, Signal
from amaranth.lib.cdc import ResetSynchronizer

from spec.facts import SPARTAN6

__all__ = ["Spartan6Clocks", "PLANS", "DCLK_HZ", "pll_multipliers"]

#: The default DCLK.
DCLK_HZ = 400e6

#: PLLs by DCLK: each ``{"vco": MHz, "outputs": {name: divide}, "phases": {name: degrees}}``
#: (VCO inside Spartan-6 -3's 400-1080 MHz); :func:`pll_multipliers` derives the PLL's input
#: divider and feedback multiplier from the board's oscillator. Outputs named ``io_*`` feed
#: BUFPLLs, the others BUFGs that drive the domain of that name.
PLANS = {
    200e6: [
        {"vco": 1000, "outputs": {"sync": 8, "dmd": 5, "dclk": 5, "gmii_tx": 8}, "phases": {"dclk": 90.0}},
    ],
    400e6: [
        {"vco": 1000, "outputs": {"sync": 8, "gmii_tx": 8}, "phases": {}},
        {"vco": 800, "outputs": {"io_data": 1, "io_dclk": 1, "dmd": 4}, "phases": {"io_dclk": 180.0}},
    ],
    # no DLPC410 link: a tiled display's sync master (its network port and its pulses)
    None: [
        {"vco": 1000, "outputs": {"sync": 8, "gmii_tx": 8}, "phases": {}},
    ],
}
#: The oscillator of the Atlys (the default input).
INPUT_HZ = 100e6


def pll_multipliers(input_hz, vco_mhz):
    """``(DIVCLK_DIVIDE, CLKFBOUT_MULT)`` that make ``vco_mhz`` from ``input_hz``: the smallest
    divider, the phase detector kept at or above the PLL's lowest (``spec.facts.SPARTAN6``)."""
    ratio = Fraction(int(vco_mhz * 1e6), int(input_hz))
    divide, mult = ratio.denominator, ratio.numerator
    pfd_min = SPARTAN6["pll_pfd_min"].value
    assert mult <= 64 and input_hz / divide >= pfd_min, f"no PLL makes {vco_mhz} MHz from {input_hz / 1e6} MHz"
    return divide, mult


class Spartan6Clocks(Elaboratable):
    """PLL_BASEs, BUFGs and (at DCLK 400 MHz) BUFPLLs.

    Parameters
    ----------
    clk_in : Signal
        The board oscillator.
    rst_in : Signal
        Board reset button (active high).
    dclk_hz : float
        DCLK: 400 MHz or 200 MHz; None: no DLPC410 link (the sync master's build).
    input_hz : float
        The oscillator's frequency (100 MHz on the Atlys, 125 MHz on the SVEC).

    Attributes
    ----------
    locked : Signal
        Every PLL locked.
    io : dict
        At 400 MHz: ``{"data": (ioclk, strobe), "dclk": (ioclk, strobe)}`` of the BUFPLLs.
    """

    def __init__(self, clk_in, rst_in, dclk_hz=DCLK_HZ, input_hz=INPUT_HZ):
        self.clk_in = clk_in
        self.rst_in = rst_in
        self.dclk_hz = dclk_hz
        self.input_hz = input_hz
        self.locked = Signal()
        self.io = {name: (Signal(name=f"ioclk_{name}"), Signal(name=f"strobe_{name}"))
                   for name in ("data", "dclk")} if dclk_hz == 400e6 else {}

    @staticmethod
    def domains(dclk_hz=DCLK_HZ):
        """The clock domains this block drives; the top that owns them adds them."""
        return [ClockDomain(name) for plan in PLANS[dclk_hz] for name in plan["outputs"]
                if not name.startswith("io_")]

    @staticmethod
    def frequencies(dclk_hz=DCLK_HZ):
        """``{domain: Hz}`` of the plan (whatever the oscillator: the VCOs are the plan's)."""
        return {name: plan["vco"] / div * 1e6 for plan in PLANS[dclk_hz]
                for name, div in plan["outputs"].items() if not name.startswith("io_")}

    def elaborate(self, platform):
        m = Module()
        plans = PLANS[self.dclk_hz]
        locks = []
        clk_in = self.clk_in
        raw = {}
        for index, plan in enumerate(plans):
            feedback, lock = Signal(name=f"pll{index}_feedback"), Signal(name=f"pll{index}_locked")
            divide, mult = pll_multipliers(self.input_hz, plan["vco"])
            params = dict(
                p_BANDWIDTH="OPTIMIZED", p_CLK_FEEDBACK="CLKFBOUT", p_COMPENSATION="INTERNAL",
                p_CLKIN_PERIOD=1e9 / self.input_hz, p_DIVCLK_DIVIDE=divide, p_CLKFBOUT_MULT=mult,
                p_CLKFBOUT_PHASE=0.0, i_CLKIN=clk_in, i_RST=self.rst_in, i_CLKFBIN=feedback,
                o_CLKFBOUT=feedback, o_LOCKED=lock,
            )
            for i, (name, divide) in enumerate(plan["outputs"].items()):
                raw[name] = Signal(name=f"pll_{name}")
                params.update({f"p_CLKOUT{i}_DIVIDE": divide, f"p_CLKOUT{i}_DUTY_CYCLE": 0.5,
                               f"p_CLKOUT{i}_PHASE": plan["phases"].get(name, 0.0), f"o_CLKOUT{i}": raw[name]})
            m.submodules[f"pll{index}"] = Instance("PLL_BASE", **params)
            locks.append(lock)
        m.d.comb += self.locked.eq(sum(locks) == len(locks))

        for name, signal in raw.items():
            if not name.startswith("io_"):
                m.submodules[f"bufg_{name}"] = Instance("BUFG", i_I=signal, o_O=ClockSignal(name))
                m.submodules[f"rst_{name}"] = ResetSynchronizer(~self.locked, domain=name)
        for name, (ioclk, strobe) in self.io.items():
            m.submodules[f"bufpll_{name}"] = Instance(
                "BUFPLL", p_DIVIDE=4, p_ENABLE_SYNC="TRUE",
                i_PLLIN=raw[f"io_{name}"], i_GCLK=ClockSignal("dmd"), i_LOCKED=self.locked,
                o_IOCLK=ioclk, o_SERDESSTROBE=strobe)
        return m
