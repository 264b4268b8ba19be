"""The blocks that ship, each as a standalone top for the resource report and the ISE tree.

One entry per block: ``name -> factory``. The factory builds the block with the geometry and
parameters it ships with. ``make resources`` synthesises each for XC6SLX45 and reports it as
``res.<name>.*``; ``make verilog`` writes each block's Verilog beside the platform top.
"""

from gateware.dlpc410.facts import DMDS


def _serialiser():
    from gateware.bitplane import Serialiser
    return Serialiser(DMDS["dlp7000"], lanes=8)


def _seq():
    from gateware.dlpc410.sequencer import Sequencer
    return Sequencer(DMDS["dlp7000"])


BLOCKS = {
    "serialiser": _serialiser,
    "seq": _seq,
}
