"""The camera misalignment experiment (:mod:`sim.bench.camera_figures`) on the sequencer's generated
Verilog (the sequencer rig, testbench :mod:`sim.tb.seq_rig_tb`): a window holding the frame sees
every level exact; a window lagging an MSB-first frame by a tenth of it loses the MSB's share from
every level of 128 and up (the jump at 128), much less below; leading it loses only the low planes'
share at the end of the frame."""

import numpy as np
import pytest

from sim.bench.camera_figures import misalignment
from spec.registers import PlaneOrder


@pytest.mark.verilog
def test_the_jump_at_128_on_the_gateware(test_name):
    curves = misalignment(PlaneOrder.MSB_FIRST, shifts=(0, 10, -10), name=test_name)
    assert np.abs(curves[0]).max() == 0
    lag, lead = curves[10], curves[-10]
    # a tenth of the frame is about 25.6 LSB of the MSB's time (the frame is not all light)
    assert -28 < lag[128:].max() and lag[128:].min() < -20
    assert lag[:128].min() > -20
    assert lag[128] - lag[127] < -20
    # leading: the frame's end is lost (its low planes); 128 has none there
    assert lead[127] < -10 and lead[128] - lead[127] > 10


@pytest.mark.verilog
def test_the_interleaved_order_leads_with_its_msb(test_name):
    """The interleaved order (7 1 6 2 5 3 4 0) on the gateware: aligned, every level exact; its
    most significant plane comes first, so a lagging window loses the MSB's share from every
    level of 128 and up, as with MSB first."""
    curves = misalignment(PlaneOrder.TABLE, shifts=(0, 10), name=test_name)
    assert np.abs(curves[0]).max() == 0
    assert curves[10][128] - curves[10][127] < -20
