"""1000BASE-X PCS (IEEE 802.3 clauses 36, 37) between a transceiver's 10-bit parallel interface and GMII.

8b/10b in fabric (:mod:`.code_groups`), code-group alignment on the comma (:mod:`.align`), the
receive synchronisation state machine (:mod:`.sync`), the transmit and receive ordered-set
processes (:mod:`.transmit`, :mod:`.receive`), and clause 37 auto-negotiation (:mod:`.autoneg`);
:class:`Pcs` joins them.
"""

from .pcs import Pcs

__all__ = ["Pcs"]
