"""Facts about the Marvell 88E1111 PHY that the management block needs, with their sources.

Sources
-------
802.3     IEEE 802.3 clause 22 (MDIO frame, MDC <= 2.5 MHz, basic registers)
88E1111   Marvell 88E1111 datasheet (register 17 "PHY specific status", reset timing)
Atlys     Digilent Atlys reference manual (PHY strapping)
"""

from gateware.dlpc410.facts import Fact

__all__ = ["PHY"]

PHY = {
    "mdc_max": Fact(2.5e6, "Hz", "802.3 22.2.2.13", "high", "the 88E1111 accepts up to 8.3 MHz"),
    "reset_low": Fact(10e-3, "s", "88E1111 reset timing", "high", "RESETn low at least 10 ms"),
    "reset_to_mdio": Fact(5e-3, "s", "88E1111 reset timing", "medium", "wait after reset release"),
    "phy_address": Fact(0b00111, "", "Atlys strapping", "medium", "PHYAD[4:0] as strapped on the board"),
    "reg_status": Fact(17, "", "88E1111 register 17", "high", "PHY specific status"),
    "status_link_bit": Fact(10, "", "88E1111 register 17.10", "high", "link (real time)"),
    "status_speed_lsb": Fact(14, "", "88E1111 register 17.15:14", "high", "10 = 1000, 01 = 100, 00 = 10 Mb/s"),
    "status_resolved_bit": Fact(11, "", "88E1111 register 17.11", "high", "speed and duplex resolved"),
}
