"""The bit-plane store: frame slots in DDR2 through the Spartan-6 MCB, and the plane reader.

:class:`Store` is the whole block (slots, writer, reader); :mod:`.layouts` is what it exchanges
with the sequencer, :mod:`.mcb` the MCB user port, :mod:`.addresses` where words live in DDR2.
"""

from .addresses import AddressMap
from .reader import Reader
from .slots import FrameSlots, SlotCounters, SlotState
from .store import Store
from .writer import Writer

__all__ = ["AddressMap", "FrameSlots", "Reader", "SlotCounters", "SlotState", "Store", "Writer"]
