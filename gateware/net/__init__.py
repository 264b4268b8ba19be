"""The network stack (``sync``): Ethernet II, ARP, IPv4, ICMP echo, UDP; one module per protocol.

:class:`.stack.Stack` composes them; :class:`.ingest.Ingest` puts the application protocol
behind it: the block that sits between the MAC and the bit-plane serialiser; :class:`.port.
EthernetPort` is the whole Ethernet side, GMII pins to image rows, the block the system top
uses. (Import them from their modules: the protocol package builds on this package's layouts.)
"""
