"""Test fixture: a store stand-in that answers the sequencer's plane requests.

Not the product's reader: a memory (or a ramp generator, for full-size DMDs) with the store's
ports as the sequencer sees them (:mod:`gateware.store.layouts`), wrapped with the sequencer in
:class:`SequencerBench` so that the Amaranth simulator and Verilator run the same thing.
"""

import numpy as np
from amaranth import Array, Cat, Const, Module, Signal
from amaranth.lib import data, memory, stream, wiring
from amaranth.lib.wiring import In, Out

from gateware.dlpc410 import interface
from gateware.dlpc410.sequencer import Sequencer, Status
from gateware.registers import Registers
from gateware.store.layouts import FrameInfo, PlaneRequest
from sim.models import bitplane
from spec.registers import TIME_BITS

__all__ = ["PlaneSource", "SequencerBench", "ramp_image"]


def ramp_image(dmd, slot):
    """The image the ramp generator holds in ``slot``: every grey level on every row."""
    r = np.arange(dmd.rows)[:, None]
    c = np.arange(dmd.columns)[None, :]
    return ((c + r + 37 * slot) & 255).astype(np.uint8)


class PlaneSource(wiring.Component):
    """Answers :class:`PlaneRequest` with words, one per cycle; offers ``frames`` in turn.

    ``images``: {slot: 8-bit image} kept in a memory, or None for the ramp generator
    (:func:`ramp_image`, every block occupied). ``frames``: list of (slot, bit depth) or
    (slot, bit depth, ready): a frame is offered once ``now`` (the sequencer's time base) has
    reached its ``ready`` (default 0), after the frames before it were taken or dropped.
    """

    def __init__(self, dmd, frames, images=None, slots=2):
        self._dmd, self._frames, self._images, self._slots = dmd, frames, images, slots
        super().__init__({
            "requests": In(stream.Signature(PlaneRequest)),
            "words": Out(stream.Signature(64)),
            "frames": Out(stream.Signature(FrameInfo)),
            "occ_slot": In(4),
            "occupancy": Out(data.ArrayLayout(8, dmd.blocks)),
            "now": In(TIME_BITS),
        })

    def elaborate(self, platform):
        m = Module()
        dmd = self._dmd
        wpr = dmd.words_per_row
        req = Signal(PlaneRequest)
        busy = Signal()
        word = Signal(range(wpr))
        rows_left = Signal(12)
        with m.If(~busy):
            m.d.comb += self.requests.ready.eq(1)
            with m.If(self.requests.valid):
                m.d.sync += [req.eq(self.requests.payload), busy.eq(1), word.eq(0),
                             rows_left.eq(self.requests.payload.row_count)]
        with m.Else():
            m.d.comb += self.words.valid.eq(1)
            with m.If(self.words.ready):
                m.d.sync += word.eq(word + 1)
                with m.If(word == wpr - 1):
                    m.d.sync += [word.eq(0), req.first_row.eq(req.first_row + 1),
                                 rows_left.eq(rows_left - 1)]
                    with m.If(rows_left == 1):
                        m.d.sync += busy.eq(0)

        occ_rows = []
        if self._images is None:
            base = Signal(8)
            m.d.comb += base.eq(word * 64 + req.first_row + 37 * req.slot)
            m.d.comb += self.words.payload.eq(Cat(
                (base + i)[:8].bit_select(req.plane, 1) for i in range(64)))
            occ_rows = [[255] * dmd.blocks for _ in range(self._slots)]
        else:
            depth = self._slots * 8 * dmd.rows * wpr
            init = np.zeros((self._slots, 8, dmd.rows, wpr), dtype=np.uint64)
            occ_rows = [[0] * dmd.blocks for _ in range(self._slots)]
            for slot, image in self._images.items():
                init[slot] = bitplane.plane_words(image)
                occ_rows[slot] = [int(x) for x in bitplane.occupancy(image, dmd.rows_per_block)]
            m.submodules.mem = mem = memory.Memory(shape=64, depth=depth, init=[int(x) for x in init.ravel()])
            rd = mem.read_port(domain="comb")
            m.d.comb += [rd.addr.eq(((req.slot * 8 + req.plane) * dmd.rows + req.first_row) * wpr + word),
                         self.words.payload.eq(rd.data)]
        occ = Array(Const(sum(v << (8 * b) for b, v in enumerate(row)), 8 * dmd.blocks) for row in occ_rows)
        m.d.sync += self.occupancy.as_value().eq(occ[self.occ_slot])

        index = Signal(range(len(self._frames) + 1))
        frames = Array(Const(FrameInfo.const({"slot": f[0], "frame_id": i, "bit_depth": f[1]}).as_value().value,
                             FrameInfo.as_shape().size) for i, f in enumerate(self._frames))
        ready = Array(Const(f[2] if len(f) > 2 else 0, TIME_BITS) for f in self._frames + [(0, 0)])
        m.d.comb += [self.frames.valid.eq((index < len(self._frames)) & (self.now >= ready[index])),
                     self.frames.payload.as_value().eq(frames[index])]
        with m.If(self.frames.valid & self.frames.ready):
            m.d.sync += index.eq(index + 1)
        return m


class SequencerBench(wiring.Component):
    """The sequencer with a :class:`PlaneSource`: what the tests drive."""

    def __init__(self, dmd, frames, images=None):
        self._dmd, self._frames, self._images = dmd, frames, images
        super().__init__({
            "pins": Out(interface.Signature(dmd.buses)),
            "regs": In(Registers),
            "reload": In(1),
            "at_rest": Out(1),
            "trigger_in": In(1),
            "sync_in": In(1),
            "soft_trigger": In(1),
            "sync_out": Out(1),
            "camera_out": Out(1),
            "seed": In(64),
            "reseed": In(1),
            "release": Out(stream.Signature(4)),
            "status": Out(Status),
        })

    def elaborate(self, platform):
        m = Module()
        m.submodules.seq = seq = Sequencer(self._dmd)
        m.submodules.src = src = PlaneSource(self._dmd, self._frames, self._images)
        wiring.connect(m, seq.requests, src.requests)
        wiring.connect(m, src.words, seq.words)
        wiring.connect(m, src.frames, seq.frames)
        wiring.connect(m, seq.release, wiring.flipped(self.release))
        m.d.comb += [src.occ_slot.eq(seq.occ_slot), seq.occupancy.eq(src.occupancy),
                     src.now.eq(seq.status.now)]
        wiring.connect(m, wiring.flipped(self.pins), seq.pins)
        for name in ("regs", "reload", "trigger_in", "sync_in", "soft_trigger", "seed", "reseed"):
            m.d.comb += getattr(seq, name).eq(getattr(self, name))
        for name in ("sync_out", "camera_out", "status", "at_rest"):
            m.d.comb += getattr(self, name).eq(getattr(seq, name))
        return m
