"""The GMII receive MAC in the Amaranth simulator, against :mod:`sim.models.mac_model`."""

import pytest

from gateware.mac.gmii_rx import Receiver
from sim.harness.amaranth_sim import simulate
from sim.models import mac_model as mac

CLOCKS = {"gmii_rx": 125e6}


def run_receiver(symbols, name, *, max_frame=9018):
    """Drive ``symbols`` on the pins; return the output transfers and the counters."""
    dut = Receiver(max_frame=max_frame)
    out = {"beats": []}

    async def bench(ctx):
        for d, dv, er in symbols + mac.idle(8):
            ctx.set(dut.gmii, {"d": d, "dv": dv, "er": er})
            _, _, valid, beat = await ctx.tick("gmii_rx").sample(dut.frames.valid, dut.frames.payload)
            if valid:
                out["beats"].append((int(beat.data), int(beat.last), int(beat.user)))
        out["counters"] = {v: ctx.get(dut.counters[v]) for v in mac.VERDICTS}

    simulate(dut, [bench], name=f"mac_{name}", clocks=CLOCKS, deadline=1e-2)
    return mac.split_frames(out["beats"]), out["counters"]


def check(symbols, name, *, max_frame=9018):
    """Run the receiver and compare frame by frame with the reference; return the reference."""
    expected = mac.receive(symbols, max_frame)
    frames, counters = run_receiver(symbols, name, max_frame=max_frame)
    forwarded = [r for r in expected if r.data]
    assert [(len(f), bad) for f, bad in frames] == [(len(r.data), r.bad) for r in forwarded]
    for (got, bad), want in zip(frames, forwarded, strict=True):
        assert got == want.data and bad == want.bad
    assert counters == mac.counts(expected)
    return expected, frames


def back_to_back(frames, gap=12, **wire_args):
    symbols = []
    for f in frames:
        symbols += mac.wire(f, **wire_args) + mac.idle(gap)
    return symbols


def test_good_frames_back_to_back(test_name):
    """Sizes from 64 to a full 1518 and one jumbo, at the minimum gap: all forwarded intact."""
    rng = mac.seeded(1)
    frames = [mac.frame_of_length(n, rng) for n in mac.random_sizes(rng, 10, jumbo=[9018])]
    expected, got = check(back_to_back(frames), test_name)
    assert [f for f, _ in got] == [f[:-4] for f in frames]
    assert all(not bad for _, bad in got)


def assert_no_leak(frames, bad_frame):
    """No frame passed as good carries the bad frame's bytes."""
    assert not any(not bad and bad_frame[:-4].startswith(f) for f, bad in frames if f)


def good_and(bad_symbols, rng):
    """A good frame either side of the bad input, so that recovery is checked too."""
    good = mac.frame_of_length(100, rng)
    return mac.wire(good) + mac.idle(12) + bad_symbols + mac.idle(12) + mac.wire(good), good


def run_bad(bad_symbols, bad_frame, verdict, name, **kw):
    symbols, good = good_and(bad_symbols, mac.seeded(2))
    expected, frames = check(symbols, name, **kw)
    counts = mac.counts(expected)
    assert counts[verdict] == 1 and counts["good"] == 2
    assert [f for f, bad in frames if not bad] == [good[:-4]] * 2
    assert_no_leak(frames, bad_frame)


def test_bad_fcs(test_name):
    frame = bytearray(mac.frame_of_length(200, mac.seeded(3)))
    frame[50] ^= 0x10
    run_bad(mac.wire(frame), bytes(frame), "bad_fcs", test_name)


@pytest.mark.parametrize("where", ["start", "middle", "fcs"])
def test_rx_er(where, test_name):
    frame = mac.frame_of_length(300, mac.seeded(4))
    index = {"start": 8, "middle": 8 + 150, "fcs": 8 + 300 - 2}[where]
    run_bad(mac.wire(frame, errors=[index]), frame, "rx_er", test_name)


def test_rx_er_in_preamble(test_name):
    frame = mac.frame_of_length(300, mac.seeded(4))
    run_bad(mac.wire(frame, errors=[3]), frame, "rx_er", test_name)


def test_runt(test_name):
    frame = mac.frame_of_length(63, mac.seeded(5))
    run_bad(mac.wire(frame), frame, "runt", test_name)


def test_oversize(test_name):
    """With the limit at 600 bytes: a 601-byte frame stops after 596 bytes and ends bad."""
    frame = mac.frame_of_length(601, mac.seeded(6))
    run_bad(mac.wire(frame), frame, "oversize", test_name, max_frame=600)


@pytest.mark.parametrize("preamble", [0, 1, 2])
def test_short_preamble_accepted(preamble, test_name):
    frame = mac.frame_of_length(64, mac.seeded(7))
    _, got = check(mac.wire(frame, preamble=preamble) + mac.idle(12), test_name)
    assert got == [(frame[:-4], False)]


@pytest.mark.parametrize("kind", ["wrong_byte", "missing_sfd"])
def test_preamble_error(kind, test_name):
    frame = mac.frame_of_length(120, mac.seeded(8))
    if kind == "wrong_byte":
        symbols = mac.wire(frame, preamble_bytes=[0x55, 0x55, 0x54, 0x55, 0x55])
    else:
        symbols = mac.wire(frame, sfd=False, preamble=7)[:7]
    run_bad(symbols, frame, "preamble", test_name)


def test_tiny_bursts_leave_nothing(test_name):
    """Bursts of 0 to 4 bytes after the SFD are runts and forward no byte at all."""
    symbols = []
    for n in range(5):
        symbols += mac.wire(bytes(range(n))) + mac.idle(3)
    expected, frames = check(symbols, test_name)
    assert frames == [] and mac.counts(expected)["runt"] == 5


def test_latency_figures():
    """``eth.mac_rx_latency_cycles`` as the benchmark measures it: the pin register, the FCS
    register, and the output register after ``rx_dv`` falls; through the crossing, the FIFO's
    Gray pointer register and its two synchroniser stages add three more."""
    from sim.bench.mac_figures import rx_latency
    assert rx_latency() == 3
    assert rx_latency(path=True) == 6
