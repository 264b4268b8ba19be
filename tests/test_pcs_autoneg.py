"""Clause 37 auto-negotiation in the Amaranth simulator: two :class:`gateware.pcs.Pcs` back to back
over lines that slip bits, each negotiating with the other, against the auto-negotiation machine
of :mod:`sim.models.pcs_model` (written apart from the standard's figure 37-6) fed what each
side's machine was fed; then frames each way, a partner that restarts, and a run of bit errors."""

import random

from amaranth import Module
from amaranth.hdl import Elaboratable

from gateware.pcs import Pcs
from gateware.pcs.autoneg import ACK, FULL_DUPLEX, AnState
from sim.harness.amaranth_sim import simulate
from sim.models import pcs_model as model
from sim.models.pcs_stim import PREAMBLE, Line, frames_of, gmii_of, random_frames

LINK_TIMER = 200
SIDES = ("near", "far")


class Pair(Elaboratable):
    """Two PCSs whose lines the testbench joins, each side's ``tx_code`` into the other's ``rx_bits``."""

    def __init__(self):
        self.near = Pcs(link_timer=LINK_TIMER)
        self.far = Pcs(link_timer=LINK_TIMER)

    def elaborate(self, platform):
        m = Module()
        m.submodules.near, m.submodules.far = self.near, self.far
        return m


def traffic(seed, cycles):
    """GMII for ``cycles`` cycles: distinct random frames with gaps; and the frames, those that fit."""
    rng = random.Random(seed)
    frames, gmii = [], []
    while True:
        frame, gap = random_frames(rng, 1)[0], rng.randrange(12, 30)
        more = gmii_of([frame], [gap], lead=0)
        if len(gmii) + len(more) > cycles:
            return gmii + [(0, 0, 0)] * (cycles - len(gmii)), frames
        frames.append(frame)
        gmii += more


def run_pair(cycles, name, *, pause=(1, 2), events=None, gmii=None, slips=(3, 7), enable=True):
    """Run the pair for ``cycles``; ``events(n, ctx, pair, lines)`` before each cycle. Gives, for
    each side, its auto-negotiation state after each cycle, the model's, GMII received, and the
    end's negotiated abilities and restarts."""
    pair = Pair()
    idle = [(0, 0, 0)] * cycles
    gmii = gmii or {side: idle for side in SIDES}
    out = {side: {"states": [], "model": [], "rx": []} for side in SIDES}

    async def bench(ctx):
        lines = {"near": Line(slips[0]), "far": Line(slips[1])}  # into each side
        models = {}
        for side, ability in zip(SIDES, pause, strict=True):
            ctx.set(getattr(pair, side).pause, ability)
            ctx.set(getattr(pair, side).mr_an_enable, enable)
            models[side] = model.AutoNeg(FULL_DUPLEX | ability << 7, LINK_TIMER, enable=enable)
        for n in range(cycles):
            if events:
                events(n, ctx, pair, lines)
            fed = {}
            for side in SIDES:
                pcs = getattr(pair, side)
                ctx.set(pcs.gmii_tx, dict(zip(("en", "er", "d"), gmii[side][n], strict=True)))
                an = pcs.autoneg
                word = ctx.get(an.configs.payload) if ctx.get(an.configs.valid) else None
                fed[side] = {"word": word, "idle": ctx.get(an.idle), "invalid": ctx.get(an.invalid),
                             "sync_status": ctx.get(an.sync_status), "restart": ctx.get(an.mr_restart_an)}
            await ctx.tick()
            codes = {side: ctx.get(getattr(pair, side).tx_code) for side in SIDES}
            for side, other in (("near", "far"), ("far", "near")):
                pcs = getattr(pair, side)
                ctx.set(pcs.rx_bits, lines[side].word(codes[other]))
                pins = ctx.get(pcs.gmii_rx)
                out[side]["rx"].append((int(pins.dv), int(pins.er), int(pins.d)))
                out[side]["states"].append(AnState(ctx.get(pcs.autoneg.state)).name)
                models[side].ability = ctx.get(pcs.mr_adv_ability)
                out[side]["model"].append(models[side].step(**fed[side]))
        for side in SIDES:
            pcs = getattr(pair, side)
            out[side].update(lp=ctx.get(pcs.mr_lp_adv_ability), complete=ctx.get(pcs.mr_an_complete),
                             restarts=ctx.get(pcs.restarts), ours=ctx.get(pcs.mr_adv_ability),
                             model_lp=models[side].lp_ability, model_restarts=models[side].restarts)

    simulate(pair, [bench], name=name, deadline=1.0)
    return out


def visits(states):
    """The states in the order entered."""
    return [s for n, s in enumerate(states) if n == 0 or states[n - 1] != s]


def assert_agrees_with_model(out):
    for side in SIDES:
        assert out[side]["states"] == out[side]["model"]
        assert (out[side]["lp"], out[side]["restarts"]) == (out[side]["model_lp"], out[side]["model_restarts"])


def assert_whole(received, sent):
    """Every frame received is one sent, whole (its first preamble byte may be lost to /S/)."""
    for frame in received:
        assert any(frame in (PREAMBLE + f, (PREAMBLE + f)[1:]) for f in sent), frame


def test_both_sides_reach_link_ok(test_name):
    """From power-on each side goes through the figure's states in order to LINK_OK, holds it,
    and reports the other's base page, as acknowledged; as the model does, cycle by cycle."""
    out = run_pair(1500, test_name)
    assert_agrees_with_model(out)
    for side, other in (("near", "far"), ("far", "near")):
        assert visits(out[side]["states"]) == [
            "AN_ENABLE", "AN_RESTART", "ABILITY_DETECT", "ACKNOWLEDGE_DETECT", "COMPLETE_ACKNOWLEDGE",
            "IDLE_DETECT", "LINK_OK"]
        assert out[side]["complete"] == 1 and out[side]["restarts"] == 0
        assert out[side]["lp"] == out[other]["ours"] | ACK
    assert out["near"]["ours"] == FULL_DUPLEX | 1 << 7 and out["far"]["ours"] == FULL_DUPLEX | 2 << 7


def test_frames_pass_once_the_link_is_up(test_name):
    """Both MACs send from power-on: frames sent before LINK_OK are dropped, every frame given is
    whole, and frames pass both ways once the link is up."""
    cycles = 3000
    gmii, sent = {}, {}
    for seed, side in enumerate(SIDES):
        gmii[side], sent[side] = traffic(seed, cycles)
    out = run_pair(cycles, test_name, gmii=gmii)
    for side, other in (("near", "far"), ("far", "near")):
        up = out[side]["states"].index("LINK_OK")
        received = frames_of(out[side]["rx"])
        assert_whole(received, sent[other])
        assert len(received) >= 10
        assert not any(out[side]["rx"][n][0] for n in range(up))


def test_a_partner_restarting_is_followed(test_name):
    """With the link up and frames both ways, the far side restarts with new abilities: it sends
    all-zero words for a link timer, then its new page. The near side leaves LINK_OK, counts a
    restart, and comes back with the new page; frames are whole throughout and pass again."""
    cycles, at = 4000, 1300
    gmii, sent = {}, {}
    for seed, side in enumerate(SIDES):
        gmii[side], sent[side] = traffic(seed + 10, cycles)

    def events(n, ctx, pair, lines):
        if n == at:
            ctx.set(pair.far.pause, 3)
        ctx.set(pair.far.mr_restart_an, n == at)

    out = run_pair(cycles, test_name, gmii=gmii, events=events)
    assert_agrees_with_model(out)
    near = out["near"]
    assert near["states"][at - 1] == "LINK_OK"
    later = visits(near["states"][at:])
    assert later[0] == "LINK_OK" and later[1] == "AN_ENABLE" and later[-1] == "LINK_OK"
    assert near["restarts"] == 1 and out["far"]["restarts"] == 1
    assert near["lp"] == FULL_DUPLEX | 3 << 7 | ACK
    assert out["far"]["lp"] == FULL_DUPLEX | 1 << 7 | ACK
    for side, other in (("near", "far"), ("far", "near")):
        received = frames_of(out[side]["rx"])
        assert_whole(received, sent[other])
        back = len(out[side]["states"]) - out[side]["states"][::-1].index("AN_ENABLE")
        assert frames_of(out[side]["rx"][back:]), "no frame after the link came back"


def test_loss_of_sync_restarts_negotiation(test_name):
    """A run of bit errors into the near side loses its sync: it goes back to AN_ENABLE, sends
    all-zero words, which restarts the far side too, and both come back to LINK_OK."""
    cycles, at = 3000, 1200

    def events(n, ctx, pair, lines):
        if at <= n < at + 30:
            lines["near"].bits = "0" * len(lines["near"].bits)

    out = run_pair(cycles, test_name, events=events)
    assert_agrees_with_model(out)
    near, far = out["near"], out["far"]
    assert near["states"][at - 1] == "LINK_OK" and far["states"][at - 1] == "LINK_OK"
    assert "AN_ENABLE" in near["states"][at:] and "AN_ENABLE" in far["states"][at:]
    assert near["restarts"] == 1 and far["restarts"] == 1
    assert near["states"][-1] == far["states"][-1] == "LINK_OK"
    assert near["lp"] == far["ours"] | ACK and far["lp"] == near["ours"] | ACK


def test_without_an_enable_data_passes_at_once(test_name):
    """``mr_an_enable`` low on both sides: AN_ENABLE until in sync (idles sent, no configuration
    words), then AN_DISABLE_LINK_OK, and frames pass both ways."""
    cycles = 1200
    gmii, sent = {}, {}
    for seed, side in enumerate(SIDES):
        gmii[side], sent[side] = traffic(seed + 20, cycles)
    out = run_pair(cycles, test_name, gmii=gmii, enable=False)
    assert_agrees_with_model(out)
    for side, other in (("near", "far"), ("far", "near")):
        assert visits(out[side]["states"]) == ["AN_ENABLE", "AN_DISABLE_LINK_OK"]
        received = frames_of(out[side]["rx"])
        assert_whole(received, sent[other])
        assert len(received) >= len(sent[other]) - 1
