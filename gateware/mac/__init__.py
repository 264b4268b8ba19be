"""GMII MAC: receive (``gmii_rx``), transmit (``gmii_tx``) and the crossing into ``sync``.

The stack connects to :class:`ReceivePath` and :class:`TransmitPath` (``sync``-domain
:class:`layouts.ByteBeat` streams); :mod:`.axis` gives the same with AXI4-Stream port names.
"""

from .path import ReceivePath, TransmitPath

__all__ = ["ReceivePath", "TransmitPath"]
