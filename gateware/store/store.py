"""The bit-plane store as one block: frame slots, DDR2 writer and plane reader.

Serialiser words in (``sync``), planes out to the sequencer (``dmd``), two MCB ports to the
memory controller (port 0 in ``sync`` for writing, 64 bits; port 1 in ``dmd`` for reading, 64 or
128 bits). The system top connects ``mcb_write`` and ``mcb_read`` to
:class:`gateware.platform.mcb_instance.McbInstance`; simulations connect them to
:mod:`sim.models.mcb_model`.

A memory that loses its calibration loses every frame (:mod:`.recovery`); ``lost`` tells the
sequencer's side, which plays what it holds dark and waits for a frame stored after it.
"""

from amaranth import DomainRenamer, Module
from amaranth.lib import stream, wiring
from amaranth.lib.cdc import FFSynchronizer
from amaranth.lib.wiring import Out

from ..compose import forward, members
from .layouts import LIVE_SLOTS
from .reader import Reader
from .recovery import Recovery
from .slots import FrameSlots
from .split import Split
from .writer import Writer

__all__ = ["Store"]


class Store(wiring.Component):
    """Frame slots in DDR2 with their writer and reader.

    Parameters
    ----------
    dmd : :class:`spec.facts.DmdType`
    slots : int
        Frame slots (3 to ``2**SLOT_BITS``, :class:`~gateware.store.slots.FrameSlots`).
    frame_bits : int
        Width of the serialiser's frame tag (the frame id).
    fifo_depth : int
        The reader's look-ahead in plane words.
    read_width : int
        The reader's MCB port: 64 or 128 bits (one or two plane words a port word).
    plane_words : int, optional
        Plane words per transfer on ``planes`` (default: those of a port word); 1 with a
        128-bit reader gives each port word as two transfers, for a sequencer that takes one
        word at a time.
    live : int
        The slots streaming and delta frames use (:class:`~gateware.store.slots.FrameSlots`).

    Members
    -------
    words, rows, bit_depth, sequence_length, entries, loop, sequence_start, entry_writes, counters, ask,
    frames, release, occupancy
        The ports of :class:`~gateware.store.slots.FrameSlots` but those to the writer: the
        serialiser's words and row flags, control and counters (``sync``), the sequencer's asks,
        answers, releases and occupancy lookups (``dmd``).
    requests, bad_requests
        The ports of :class:`~gateware.store.reader.Reader` (``dmd``): plane reads and requests
        dropped.
    planes : Out(stream.Signature(64 * plane_words))
        The words read (``dmd``), the first in the low bits.
    mcb_write : Out(mcb.PortSignature(64))
        The writer's MCB port 0 (``sync``).
    mcb_read : Out(mcb.PortSignature(read_width))
        The reader's MCB port 1 (``dmd``).
    lost : Out(1)
        (``dmd``) The memory lost its calibration and the store has not recovered yet: no frame
        held from before holds its words any more.
    """

    #: The reader's ports the store gives as its own.
    _READER_PORTS = ("requests", "bad_requests")

    def __init__(self, dmd, *, slots=4, frame_bits=16, fifo_depth=256, read_width=128, plane_words=None,
                 live=LIVE_SLOTS):
        port_words = read_width // 64
        self._plane_words = port_words if plane_words is None else plane_words
        assert port_words % self._plane_words == 0
        self._slots = FrameSlots(dmd, slots=slots, frame_bits=frame_bits, live=live)
        self._writer = Writer(dmd, slots=slots)
        self._reader = Reader(dmd, slots=slots, fifo_depth=fifo_depth, width=read_width)
        super().__init__({
            **members(self._slots, exclude=("store", "written", "lose", "forgotten", "sources")),
            **members(self._reader, self._READER_PORTS),
            "planes": Out(stream.Signature(64 * self._plane_words)),
            "mcb_write": self._writer.signature.members["mcb"],
            "mcb_read": self._reader.signature.members["mcb"],
            "lost": Out(1),
        })

    def elaborate(self, platform):
        m = Module()
        m.submodules.slots = slots = self._slots
        m.submodules.writer = writer = self._writer
        m.submodules.reader = reader = self._reader
        forward(m, self, slots)
        forward(m, self, reader, self._READER_PORTS)
        planes = reader.planes
        if len(planes.payload) != len(self.planes.payload):
            m.submodules.split = split = DomainRenamer("dmd")(
                Split(64 * self._plane_words, len(planes.payload) // len(self.planes.payload)))
            wiring.connect(m, planes, split.wide)
            planes = split.narrow
        wiring.connect(m, planes, wiring.flipped(self.planes))
        wiring.connect(m, slots.store, writer.words)
        wiring.connect(m, writer.written, slots.written)
        wiring.connect(m, writer.mcb, wiring.flipped(self.mcb_write))
        wiring.connect(m, reader.mcb, wiring.flipped(self.mcb_read))
        wiring.connect(m, reader.sources, slots.sources)

        m.submodules.recovery = recovery = Recovery()
        m.d.comb += [
            recovery.calib_done.eq(self.mcb_write.calib_done),
            recovery.forgotten.eq(slots.forgotten),
            slots.lose.eq(recovery.lost),
            writer.discard.eq(recovery.lost),
        ]
        m.submodules.lost_cdc = FFSynchronizer(recovery.lost, self.lost, o_domain="dmd")
        m.d.comb += reader.store_lost.eq(self.lost)
        return m
