"""A 1000BASE-X link in the Amaranth simulator: GMII frames into a :class:`gateware.pcs.Pcs`,
its code-groups over a line that slips bits, back into the same PCS's receive side, GMII out;
against :mod:`sim.models.pcs_model` (written apart) on the line and on the pins."""

import random

import pytest

from gateware.pcs import Pcs
from sim.harness.amaranth_sim import simulate
from sim.models import pcs_model as model
from sim.models.pcs_stim import PREAMBLE, Line, frames_of, gmii_of, random_frames


def run_link(gmii, name, *, slip=0, slips_at=(), configuring=()):
    """Run the PCS in loopback; the code-groups sent, the GMII received, configuration words
    received, and the end's counters."""
    dut = Pcs(autoneg=False)
    out = {"codes": [], "rx": [], "configs": []}

    async def bench(ctx):
        line = Line(slip)
        for n, (en, er, d) in enumerate(gmii):
            ctx.set(dut.gmii_tx, {"d": d, "en": en, "er": er})
            ctx.set(dut.configuring, n in configuring)
            ctx.set(dut.config, 0x41A0)
            await ctx.tick()
            if n in slips_at:
                line.slip()
            code = ctx.get(dut.tx_code)
            out["codes"].append(model.to_bits(code))
            ctx.set(dut.rx_bits, line.word(code))
            pins = ctx.get(dut.gmii_rx)
            out["rx"].append((int(pins.dv), int(pins.er), int(pins.d)))
            if ctx.get(dut.configs.valid):
                out["configs"].append(ctx.get(dut.configs.payload))
        out["counters"] = (ctx.get(dut.sync_status), ctx.get(dut.losses), ctx.get(dut.slips))

    simulate(dut, [bench], name=name, deadline=1.0)
    return out


def model_receive(codes):
    rd, groups = "-", []
    for code in codes:
        byte, control, code_error, disparity_error, rd = model.decode(code, rd)
        groups.append((byte, control, code_error or disparity_error))
    return model.receive(groups)


@pytest.mark.parametrize("slip", [0, 3, 9])
def test_frames_cross_the_link(slip, test_name):
    """Frames with idles of every parity between them: the line carries the model's
    code-groups, and each frame comes out as sent, its first preamble byte given back by /S/
    (or lost, as clause 36 loses it, when ``tx_en`` rose in an idle's second code-group)."""
    rng = random.Random(slip)
    frames = random_frames(rng, 6)
    gmii = gmii_of(frames, [12, 13, 14, 15, 12, 20])
    out = run_link(gmii, test_name, slip=slip)
    assert out["codes"] == model.transmit(gmii)
    got = frames_of(out["rx"])
    assert got == frames_of(model_receive(out["codes"])[0])
    assert len(got) == len(frames)
    lost = 0
    for sent, received in zip(frames, got, strict=True):
        wire = PREAMBLE + sent
        assert received in (wire, wire[1:])
        lost += received == wire[1:]
    assert 0 < lost < len(frames)
    assert out["counters"] == (1, 0, 1 if slip else 0)


def test_a_slip_between_frames_is_recovered(test_name):
    """A bit slips in the gap between two frames: the aligner moves to the next comma, and the
    frames after the slip come out whole."""
    rng = random.Random(7)
    frames = random_frames(rng, 4)
    gmii = gmii_of(frames, [40, 40, 40, 20])
    first_gap = 40 + len(PREAMBLE) + len(frames[0]) + 5
    out = run_link(gmii, test_name, slip=2, slips_at={first_gap})
    got = frames_of(out["rx"])
    assert len(got) == len(frames)
    for sent, received in zip(frames, got, strict=True):
        assert received in (PREAMBLE + sent, (PREAMBLE + sent)[1:])
    status, _, slips = out["counters"]
    assert status == 1 and slips == 2


def test_tx_er_is_received_as_rx_er(test_name):
    """A byte sent with ``tx_er`` goes as /V/ and comes out with ``rx_er`` in its frame."""
    frame = list(range(60))
    frame[20] = None
    out = run_link(gmii_of([frame], [20]), test_name)
    [got] = frames_of(out["rx"])
    assert got in (PREAMBLE + frame, (PREAMBLE + frame)[1:])
    assert got.count(None) == 1


def test_configuration_words_are_received(test_name):
    """/C1/ and /C2/ ordered sets with a configuration word in place of idles: the receiver
    gives the word, every /C/ after sync; then a frame still crosses."""
    frames = random_frames(random.Random(3), 1)
    gmii = gmii_of(frames, [20], lead=80)
    out = run_link(gmii, test_name, configuring=set(range(60)))
    assert out["configs"] and set(out["configs"]) == {0x41A0}
    assert len(out["configs"]) >= 10
    assert model_receive(out["codes"])[1][-len(out["configs"]):] == out["configs"]
    [got] = frames_of(out["rx"])
    assert got in (PREAMBLE + frames[0], (PREAMBLE + frames[0])[1:])
