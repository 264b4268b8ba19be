"""Digilent Atlys (XC6SLX45-CSG324-3, Marvell 88E1111 on GMII, MT47H64M16 DDR2) as the
projector's board: amaranth-boards' platform plus the DLPC410 adapter and trigger resources."""

from amaranth_boards.atlys import AtlysPlatform

from .dlpc410_adapter import dlpc410_resources, gate_resource, trigger_resources
from .mcb_instance import ATLYS_DDR2
from .pins import GmiiPins

__all__ = ["AtlysProjectorPlatform"]


class AtlysProjectorPlatform(AtlysPlatform):
    """The Atlys with the projector's resources.

    The Atlys has no ``dlpc410_ext`` connector: DIN_B and the DLPC410's single-ended lines
    cannot be placed on it (see constraints/README.md), so :attr:`dlpc410_complete` is False
    and the platform top drives only what the board can carry.
    """

    resources = AtlysPlatform.resources + dlpc410_resources() + trigger_resources() + [gate_resource()]
    #: the light gate's pin (``light_gate_out``) is placed
    light_gate = True
    dlpc410_complete = any(c.name == "dlpc410_ext" for c in AtlysPlatform.connectors)
    #: the VHDCI adapter's buses (a two-bus DMD: DLP7000)
    dlpc410_buses = 2
    #: the memory the store uses and its controller
    memory = ATLYS_DDR2
    #: the Ethernet PHY: the 88E1111 on GMII
    ethernet = GmiiPins
    #: no VCXO DAC: the clock loop's trim word goes nowhere (a tiled display needs a board with one)
    vcxo_dac = False
