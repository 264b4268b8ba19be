"""1000BASE-X PCS (IEEE 802.3 clause 36) between a transceiver's 10-bit parallel interface and GMII.

8b/10b in fabric (:mod:`.code_groups`), code-group alignment on the comma (:mod:`.align`), the
receive synchronisation state machine (:mod:`.sync`), and the transmit and receive ordered-set
processes (:mod:`.transmit`, :mod:`.receive`); :class:`Pcs` joins them. Auto-negotiation
(clause 37) is not here.
"""

from .pcs import Pcs

__all__ = ["Pcs"]
