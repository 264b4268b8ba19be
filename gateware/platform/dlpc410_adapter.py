"""The DLPC410 adapter boards and the projector's other signals, as Amaranth resources.

Every pin here is an adapter assumption (see README.md here): the DLPC410 is reached through an
adapter board that plugs into the FPGA board's connectors. Two adapters are declared, on the same
tables of DLPC410 signals:

* **the VHDCI adapter** (two buses, DLP7000; :func:`dlpc410_resources`): on the Atlys it plugs
  into the VHDCI connector (JC), whose 20 LVDS pairs carry DIN_A(15:0), DCLK_A, DVALID_A, DCLK_B
  and DVALID_B. DIN_B(15:0) and the single-ended control and status lines do not fit there; they
  are declared on the adapter's second port, ``dlpc410_ext``, which a board provides as a
  connector of that name (the Atlys does not).
* **the two-FMC adapter** (four buses, DLP9500; :func:`dlpc410_fmc_resources`): one FMC LPC
  mezzanine per pair of buses (buses A and B on the first slot, C and D on the second), each slot's
  36 pairs (LA00..LA33, CLK0_M2C, CLK1_M2C) all used; the single-ended lines on a third
  connector.

The trigger input, sync output, camera-trigger output, sync input and ready output go through
level shifters on the adapter (:func:`trigger_resources`).

A board maps its connectors onto adapter pins, so moving to another board changes only the
board's platform; the core never names pins.
"""

from amaranth.build import Attrs, DiffPairs, Pins, Resource, Subsignal

__all__ = ["VHDCI_PAIRS", "FMC_PAIRS", "CONTROL_LINES", "TRIGGER_LINES", "dlpc410_resources", "gate_resource",
           "dlpc410_fmc_resources", "trigger_resources", "control_subsignals"]

LVDS = Attrs(IOSTANDARD="LVDS_25")
LVCMOS25 = Attrs(IOSTANDARD="LVCMOS25")
LVCMOS33 = Attrs(IOSTANDARD="LVCMOS33")

#: The DLPC410's single-ended lines, in the adapters' pin order: (name, width, direction from the
#: FPGA). 25 outputs and 10 inputs, 35 pins.
CONTROL_LINES = [
    ("rowmd", 2, "o"), ("rowad", 11, "o"), ("blkmd", 2, "o"), ("blkad", 4, "o"), ("rst2blkz", 1, "o"),
    ("comp_data", 1, "o"), ("ns_flip", 1, "o"), ("wdt_enblz", 1, "o"), ("pwr_float", 1, "o"), ("arstz", 1, "o"),
    ("init_active", 1, "i"), ("rst_active", 1, "i"), ("ecp2_finished", 1, "i"), ("dmd_type", 4, "i"),
    ("ddc_version", 3, "i"),
]

#: The trigger and tiled-display lines: (resource name, direction), in the adapters' pin order.
TRIGGER_LINES = [("trigger_in", "i"), ("sync_out", "o"), ("camera_trigger_out", "o"), ("sync_in", "i"),
                 ("ready_out", "o")]

#: The VHDCI connector's differential pairs as (P pin, N pin) connector pin numbers, in the
#: order of amaranth-boards' Atlys "vhdci" connector (P pins 1..34 with gaps, N = P + 34).
VHDCI_PAIRS = [(str(p), str(p + 34))
               for p in (1, 3, 4, 6, 7, 9, 10, 12, 13, 15, 20, 22, 23, 25, 26, 28, 29, 31, 32, 34)]

#: The VHDCI adapter's pair assignment on the VHDCI connector.
VHDCI_USE = {
    "din_a": list(range(16)),
    "dclk_a": [16],
    "dvalid_a": [17],
    "dclk_b": [18],
    "dvalid_b": [19],
}

#: The VHDCI adapter's second port: DIN_B on pairs (1, 17) .. (16, 32), the control lines from 33.
EXT_PAIRS = [(str(p), str(p + 16)) for p in range(1, 17)]
EXT_CONTROL_PINS = [str(p) for p in range(33, 68)]

#: An FMC LPC connector's user pairs, in the VITA 57.1 signal names of the board's "fmc"
#: connectors: LA00..LA33 (the clock-capable ones named _CC), then CLK0_M2C and CLK1_M2C.
FMC_PAIRS = [(f"{stem}_P", f"{stem}_N")
             for stem in [f"LA{i:02d}{'_CC' if i in (0, 1, 17, 18) else ''}" for i in range(34)]
             + ["CLK0_M2C", "CLK1_M2C"]]


def fmc_use(first, second):
    """The two-FMC adapter's pair assignment on one slot carrying buses ``first`` and ``second``:
    their DIN on LA00..LA15 and LA16..LA31, the first bus's DCLK and DVALID on LA32 and LA33, the
    second's on CLK0_M2C and CLK1_M2C (driven by the FPGA: the adapter is a mezzanine only in
    shape)."""
    return {
        f"din_{first}": list(range(16)),
        f"din_{second}": list(range(16, 32)),
        f"dclk_{first}": [32],
        f"dvalid_{first}": [33],
        f"dclk_{second}": [34],
        f"dvalid_{second}": [35],
    }


def pair_subsignals(use, pairs, conn):
    """LVDS output subsignals: ``use`` maps each signal to indices into ``pairs`` ((P, N)
    connector pins) on connector ``conn``."""
    return [Subsignal(name, DiffPairs(" ".join(pairs[i][0] for i in indices), " ".join(pairs[i][1] for i in indices),
                                      dir="o", conn=conn), LVDS)
            for name, indices in use.items()]


def control_subsignals(pins, conn, attrs=LVCMOS25):
    """The :data:`CONTROL_LINES` on connector ``conn``'s ``pins``, in order."""
    assert len(pins) >= sum(width for _name, width, _dir in CONTROL_LINES)
    subsignals, at = [], 0
    for name, width, direction in CONTROL_LINES:
        subsignals.append(Subsignal(name, Pins(" ".join(pins[at:at + width]), dir=direction, conn=conn), attrs))
        at += width
    return subsignals


def dlpc410_resources():
    """The VHDCI adapter: resources ``dlpc410`` (the high-speed half on VHDCI) and
    ``dlpc410_ext`` (the rest, on the adapter's second port)."""
    fast = Resource("dlpc410", 0, *pair_subsignals(VHDCI_USE, VHDCI_PAIRS, ("vhdci", 0)))
    ext = Resource("dlpc410_ext", 0,
                   *pair_subsignals({"din_b": list(range(16))}, EXT_PAIRS, ("dlpc410_ext", 0)),
                   *control_subsignals(EXT_CONTROL_PINS, ("dlpc410_ext", 0)))
    return [fast, ext]


def dlpc410_fmc_resources(control_conn, control_pins):
    """The two-FMC adapter: resource ``dlpc410`` (buses A and B on connector ``("fmc", 0)``, C and
    D on ``("fmc", 1)``) and ``dlpc410_ext`` (the control lines on ``control_conn``'s
    ``control_pins``, in order)."""
    fast = Resource("dlpc410", 0,
                    *pair_subsignals(fmc_use("a", "b"), FMC_PAIRS, ("fmc", 0)),
                    *pair_subsignals(fmc_use("c", "d"), FMC_PAIRS, ("fmc", 1)))
    ext = Resource("dlpc410_ext", 0, *control_subsignals(control_pins, control_conn))
    return [fast, ext]


def gate_resource(conn=("pmod", 0), pin="8", attrs=LVCMOS33):
    """The light gate's output (``light_gate_out``, to the light source's driver) on connector
    ``conn``'s ``pin``: by default the Atlys's PMOD JB pin 8, beside the trigger lines."""
    return Resource("light_gate_out", 0, Pins(pin, dir="o", conn=conn), attrs)


def trigger_resources(conn=("pmod", 0), pins=("1", "2", "3", "4", "7"), attrs=LVCMOS33):
    """The :data:`TRIGGER_LINES` on connector ``conn``'s ``pins``: by default the Atlys's PMOD JB
    (pins 1, 2, 3, 4, 7)."""
    return [Resource(name, 0, Pins(pin, dir=direction, conn=conn), attrs)
            for (name, direction), pin in zip(TRIGGER_LINES, pins, strict=True)]
