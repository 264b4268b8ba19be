"""The byte stream between the MAC and the stack, in both directions.

Shaped like AXI4-Stream so that a vendor MAC can be swapped in: one byte per transfer, ``last``
on the final byte of a frame, and on receive ``user`` (valid with ``last``) set when the MAC's
verdict on the frame is bad (FCS, rx_er, runt, oversize, preamble). Frames carry destination MAC
to the end of the payload: no preamble, no SFD, no FCS. On transmit ``user`` asks the MAC to
abort the frame (send it with a bad FCS).
"""

from amaranth.lib import data

__all__ = ["ByteBeat"]


class ByteBeat(data.Struct):
    data: 8
    last: 1
    user: 1
