"""The DLPC410 adapter board and the projector's other signals, as Amaranth resources.

Assumption (see README.md here): the DLPC410 is reached through an adapter board. On the
Atlys it plugs into the VHDCI connector (JC), whose 20 LVDS pairs carry the high-speed half of
the link: DIN_A(15:0), DCLK_A, DVALID_A, DCLK_B, DVALID_B. DIN_B(15:0) and the single-ended
control and status lines do not fit there; they are declared on the adapter's second port,
``dlpc410_ext``, which a board provides as a connector of that name. The trigger input, sync
output and camera-trigger output use the PMOD header (JB) through level shifters on the adapter.

The adapter's own pinout (adapter pin -> signal) is the single table below; a board maps its
connectors onto adapter pins, so moving to another board changes only the board's platform.
"""

from amaranth.build import Attrs, DiffPairs, Pins, Resource, Subsignal

__all__ = ["VHDCI_PAIRS", "dlpc410_resources", "trigger_resources"]

#: The VHDCI connector's differential pairs as (P pin, N pin) connector pin numbers, in the
#: order of amaranth-boards' Atlys "vhdci" connector (P pins 1..34 with gaps, N = P + 34).
VHDCI_PAIRS = [(p, p + 34) for p in (1, 3, 4, 6, 7, 9, 10, 12, 13, 15, 20, 22, 23, 25, 26, 28, 29, 31, 32, 34)]

#: Adapter pair assignment on the VHDCI connector.
VHDCI_USE = {
    "din_a": list(range(16)),
    "dclk_a": [16],
    "dvalid_a": [17],
    "dclk_b": [18],
    "dvalid_b": [19],
}

LVDS = Attrs(IOSTANDARD="LVDS_25")


def _pairs(indices, direction):
    p = " ".join(str(VHDCI_PAIRS[i][0]) for i in indices)
    n = " ".join(str(VHDCI_PAIRS[i][1]) for i in indices)
    return DiffPairs(p, n, dir=direction, conn=("vhdci", 0))


def dlpc410_resources():
    """Resources ``dlpc410`` (the high-speed half on VHDCI) and ``dlpc410_ext`` (the rest)."""
    fast = Resource(
        "dlpc410", 0,
        *(Subsignal(name, _pairs(idx, "o"), LVDS) for name, idx in VHDCI_USE.items()),
    )
    # Adapter port 2: pin numbers of the adapter's second connector, "dlpc410_ext".
    ext_pins = {
        "din_b": ("1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16", "17 18 19 20 21 22 23 24 25 26 27 28 29 30 31 32", "o"),
    }
    single = [
        ("rowmd", "33 34", "o"), ("rowad", "35 36 37 38 39 40 41 42 43 44 45", "o"),
        ("blkmd", "46 47", "o"), ("blkad", "48 49 50 51", "o"), ("rst2blkz", "52", "o"),
        ("comp_data", "53", "o"), ("ns_flip", "54", "o"), ("wdt_enblz", "55", "o"),
        ("pwr_float", "56", "o"), ("arstz", "57", "o"),
        ("init_active", "58", "i"), ("rst_active", "59", "i"), ("ecp2_finished", "60", "i"),
        ("dmd_type", "61 62 63 64", "i"), ("ddc_version", "65 66 67", "i"),
    ]
    ext = Resource(
        "dlpc410_ext", 0,
        *(Subsignal(name, DiffPairs(p, n, dir=d, conn=("dlpc410_ext", 0)), LVDS)
          for name, (p, n, d) in ext_pins.items()),
        *(Subsignal(name, Pins(pins, dir=d, conn=("dlpc410_ext", 0)), Attrs(IOSTANDARD="LVCMOS25"))
          for name, pins, d in single),
    )
    return [fast, ext]


def trigger_resources():
    """Trigger in, sync out, camera trigger out, sync in (from a tiled display's sync master) and
    the ready line back to it on PMOD JB (pins 1, 2, 3, 4, 7)."""
    io = Attrs(IOSTANDARD="LVCMOS33")
    return [
        Resource("trigger_in", 0, Pins("1", dir="i", conn=("pmod", 0)), io),
        Resource("sync_out", 0, Pins("2", dir="o", conn=("pmod", 0)), io),
        Resource("camera_trigger_out", 0, Pins("3", dir="o", conn=("pmod", 0)), io),
        Resource("sync_in", 0, Pins("4", dir="i", conn=("pmod", 0)), io),
        Resource("ready_out", 0, Pins("7", dir="o", conn=("pmod", 0)), io),
    ]
