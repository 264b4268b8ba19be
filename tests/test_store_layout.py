"""The store's DDR2 layout for every geometry, checked in pure Python: the address map against
the seed design's figures, and full frames through the MCB model with the writer's and the
reader's traffic, read back against numpy (the gateware runs this traffic on the test geometry
in the simulators; here the full geometries)."""

import numpy as np
import pytest

from gateware.store.addresses import MEMORY_BYTES, PLANES, AddressMap
from sim.models import store_stim
from sim.models.mcb_model import McbModel, McbTiming
from spec.facts import DMDS


def test_xga_plane_is_0x3000_words():
    amap = AddressMap(DMDS["dlp7000"], 16)
    assert amap.plane_bytes // 8 == 0x3000 == 12_288
    assert amap.address(1, 2, 3, 4) == 0xC0000 + 2 * 0x18000 + 3 * 0x80 + 4 * 8


@pytest.mark.parametrize("dmd, slots", [("dlp7000", 170), ("dlp9500", 60), ("dlp650lnir", 131), ("test", 256)])
def test_slots_and_planes_tile_the_memory(dmd, slots):
    """The projector's slots (every whole frame in 128 MiB, 256 at most: 1024 x 768, 2048 x 1080
    and 1280 x 800 bytes a frame) tile the memory: no gap, no overlap, nothing beyond it."""
    from gateware.top.system import slots_for
    geometry = DMDS[dmd]
    assert slots_for(geometry) == slots
    amap = AddressMap(geometry, slots)
    assert amap.end <= MEMORY_BYTES
    spans = sorted((amap.address(s, p), amap.address(s, p) + amap.plane_bytes)
                   for s in range(slots) for p in range(PLANES))
    pairs = zip(spans, spans[1:], strict=False)
    assert all(a_end == b_start for (_, a_end), (b_start, _) in pairs), "gap or overlap"
    assert amap.address(0, 0, geometry.rows - 1, geometry.words_per_row - 1) + 8 == amap.plane_bytes


def test_too_many_slots_refused():
    with pytest.raises(AssertionError):
        AddressMap(DMDS["dlp9500"], 64)


@pytest.mark.parametrize("dmd, depth", [("dlp7000", 8), ("dlp9500", 3)])
def test_full_frame_through_model(dmd, depth):
    geometry = DMDS[dmd]
    amap = AddressMap(geometry, 3)
    model = McbModel(amap.end, timing=McbTiming(calib_delay_s=0.1e-6))
    writer = store_stim.PortDriver(model, 0, 8e-9)
    reader = store_stim.PortDriver(model, 1, 5e-9)
    image = store_stim.random_image(geometry, 1)
    store_stim.store_frame(writer, amap, image, 2, depth)
    for plane in store_stim.stored_planes(depth):
        words = reader.read(amap.address(2, plane), geometry.words_per_plane)
        store_stim.check_plane(geometry, image, plane, words, what=dmd)
    store_stim.check_writes_inside(model, geometry, 3, [2])
    assert np.count_nonzero(model.memory[: amap.address(2, 0) // 8]) == 0
