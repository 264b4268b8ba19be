"""GMII MAC: receive (``gmii_rx``), transmit (``gmii_tx``) and the crossing into ``sync``."""
