"""Stimulus and checks for the bit-plane store, shared by the Amaranth and cocotb tests.

What the store must hold, by numpy: the planes of an image at a bit depth, the occupancy map,
and the address ranges a run may write (:class:`gateware.store.addresses.AddressMap`).
"""

import dataclasses

import numpy as np

from gateware.store.addresses import PLANES, AddressMap
from spec.facts import TEST_DMD

from . import bitplane_model as bitplane
from . import serialiser_stim

#: The test geometry cut to 24 rows in 2 blocks, for the store's policy tests (which slot, which
#: frame, which counter): a quarter of the cycles per frame. Its 5-bit row field leaves rows 24 to
#: 31 beyond the frame.
SHORT_DMD = dataclasses.replace(TEST_DMD, name="test 128x24", rows=24, blocks=2, rows_per_block=12,
                                source="test geometry, short frames")


def stored_planes(depth):
    """Planes a frame of ``depth`` bits stores, least significant first."""
    return list(range(PLANES - depth, PLANES))


def frame_beats(image, frame_id, lanes=8, rows=None, base=0, carried=0):
    """Pixel transfers of ``image`` tagged ``frame_id`` (a delta of ``base`` carrying ``carried``
    rows when that is nonzero); ``rows`` the row order (default all)."""
    return list(serialiser_stim.pixel_beats(image, lanes, frame=frame_id, row_order=rows, base=base,
                                            carried=carried))


def random_image(dmd, seed):
    return np.random.default_rng(seed).integers(0, 256, (dmd.rows, dmd.columns), dtype=np.uint8)


def plane_words(transfers, width):
    """The 64-bit plane words in ``transfers`` of ``width`` bits each, the low word first."""
    return [int(t) >> (64 * i) & (2**64 - 1) for t in transfers for i in range(width // 64)]


def check_plane(dmd, image, plane, words, first_row=0, row_count=None, what=""):
    """``words`` (read back in order) against numpy's slicing of ``image``."""
    row_count = dmd.rows if row_count is None else row_count
    want = bitplane.plane_words(image)[plane, first_row:first_row + row_count].reshape(-1)
    got = np.array([int(w) for w in words], dtype=np.uint64)
    assert got.shape == want.shape, f"{what} plane {plane}: {got.size} words read, {want.size} expected"
    bad = np.flatnonzero(got != want)
    assert bad.size == 0, (f"{what} plane {plane}: {bad.size} words differ from numpy, first at "
                           f"row {first_row + bad[0] // dmd.words_per_row} word {bad[0] % dmd.words_per_row}")


def check_occupancy(dmd, image, depth, got, what=""):
    """``got[block]`` (8-bit plane flags read from the map) against numpy's occupancy, restricted
    to the planes the frame stores (the others read as 0)."""
    keep = sum(1 << p for p in stored_planes(depth))
    want = bitplane.occupancy(image, dmd.rows_per_block) & keep
    got = np.array(got, dtype=np.uint8)
    assert np.array_equal(got, want), f"{what} occupancy {got.tolist()} != numpy {want.tolist()}"


def check_writes_inside(model, dmd, slots, allowed, since=0):
    """Every word the memory took (from ``since`` in its write log) lies in an ``allowed`` slot."""
    amap = AddressMap(dmd, slots)
    ranges = [amap.slot_range(s) for s in allowed]
    for address, _port in model.write_log[since:]:
        assert any(lo <= address < hi for lo, hi in ranges), \
            f"word written at {address:#x}, outside slots {sorted(allowed)}"


class PortDriver:
    """Drives one port of :class:`sim.models.mcb_model.McbModel` from plain Python, cycle by cycle,
    with the traffic the writer and reader make: the reference of the store's memory traffic."""

    def __init__(self, model, port=0, period=8e-9):
        self.port, self.period, self.cycle = model.ports[port], period, 0

    def tick(self, **inputs):
        self.cycle += 1
        return self.port.clock(self.cycle * self.period, **inputs)

    def until_calibrated(self):
        while not self.port.outputs["calib_done"]:
            self.tick()

    def write(self, address, words, masks=None):
        """One burst as the writer gives it: the words first, then the command."""
        while not self.port.outputs["calib_done"] or self.port.outputs["wr_count"] > 64 - len(words):
            self.tick()
        for w, mask in zip(words, masks or [0] * len(words), strict=True):
            self.tick(wr_en=1, wr_data=int(w), wr_mask=mask)
        while self.port.outputs["cmd_full"]:
            self.tick()
        self.tick(cmd_en=1, cmd_instr=0, cmd_bl=len(words) - 1, cmd_byte_addr=address)

    def read(self, address, count, lookahead=4):
        """``count`` port words from ``address`` in bursts of up to 64, ``lookahead`` in flight."""
        out, issued, reserved = [], 0, 0
        while len(out) < count:
            o = self.port.outputs
            inputs = {}
            if not o["rd_empty"]:
                inputs["rd_en"] = 1
                out.append(o["rd_data"])
                reserved -= 1
            burst = min(64, count - issued)
            if (burst and o["calib_done"] and not o["cmd_full"]
                    and reserved + burst <= 64 * lookahead):
                inputs.update(cmd_en=1, cmd_instr=1, cmd_bl=burst - 1,
                              cmd_byte_addr=address + issued * self.port.word_bytes)
                issued += burst
                reserved += burst
            self.tick(**inputs)
        return out


def store_frame(driver, amap, image, slot, depth):
    """Write ``image`` at ``depth`` into ``slot`` row by row, plane by plane, as the writer does."""
    words = bitplane.plane_words(image)
    for row in range(amap.dmd.rows):
        for plane in stored_planes(depth):
            driver.write(amap.address(slot, plane, row), words[plane, row])
