"""The network stack (``sync``): Ethernet II, ARP, IPv4, ICMP echo, UDP; one module per protocol.

:class:`.stack.Stack` composes them; the header tables live in :mod:`spec.headers`. The
application protocol sits above (:mod:`gateware.protocol`: the endpoint puts the parser and the
status reply behind the stack).
"""
