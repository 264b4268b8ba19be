"""Gateware for a DMD infrared scene projector (Spartan-6 in front of a TI DLPC410).

Packages follow the data path:

``mac``       GMII MAC (``gmii_rx`` / ``gmii_tx`` domains)
``net``       Ethernet, ARP, IPv4, ICMP, UDP (``sync``)
``protocol``  the application protocol (``sync``)
``bitplane``  8-bit pixels to 64-bit bit-plane words (``sync``)
``store``     DDR2 frame slots through the Spartan-6 MCB (``sync`` / ``dmd``)
``dlpc410``   DMD facts, the DLPC410 interface and the load/reset sequencer (``dmd``)
``platform``  the board: pins, vendor primitives, clocks
``flow``      Verilog, the ISE tree, resource reports, benchmarks
"""
