"""The network stack (``sync``): Ethernet II, ARP, IPv4, ICMP echo, UDP; one module per protocol.

:class:`.stack.Stack` composes them; :class:`.ingest.Ingest` puts the application protocol
behind it: the block that sits between the MAC and the bit-plane serialiser. (Import them from
their modules: the protocol package builds on this package's layouts.)
"""
