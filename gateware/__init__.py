"""Gateware for a DMD infrared scene projector (Spartan-6 in front of a TI DLPC410).

Packages follow the data path, each importing only from those above it in this list (and from
:mod:`spec`, the plain-Python definitions it shares with the host):

``wire``, ``registers``, ``cdc``, ``compose``
              the bottom: Amaranth views of :mod:`spec`'s tables, clock-domain crossings, wrappers
``mac``       GMII MAC (``gmii_rx`` / ``gmii_tx`` domains)
``net``       Ethernet, ARP, IPv4, ICMP, UDP (``sync``)
``protocol``  the application protocol, the network endpoint and the Ethernet port (``sync``)
``bitplane``  8-bit pixels to 64-bit bit-plane words (``sync``)
``store``     DDR2 frame slots through the Spartan-6 MCB (``sync`` / ``dmd``)
``dlpc410``   the DLPC410 interface and the load/reset sequencer (``dmd``)
``platform``  the board: pins, vendor primitives, clocks
``top``       the projector's core and the board tops
"""
