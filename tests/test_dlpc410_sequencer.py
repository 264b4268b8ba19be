"""The sequencer (TEST_DMD, TEST_DMD4; at DCLK 400 MHz TEST_DMD_400, TEST_DMD4_400): its command
stream equals the schedule model's cycle for cycle, and every pixel receives exactly its grey level
in LSB units, under the rule-checking DLPC410 model. The runs are on the generated Verilog
(:mod:`sim.rigs.seq_rig`, testbench :mod:`sim.tb.seq_rig_tb`: one Verilator build per geometry, the
trace replayed through the model after the run); the Amaranth simulator keeps the short tests it is
the right tool for, and one scenario run on both must give the same run."""

from dataclasses import replace

import numpy as np
import pytest

from gateware.dlpc410.trigger import PIN_TO_STROBE
from sim.models import bitplane_model as bitplane
from sim.models.dlpc410_model import RULES, RuleBreak
from sim.rigs.seq_rig import run_rig
from sim.tb.plane_source import ramp_image
from sim.tb.seq_sim import INIT_CYCLES, dlpc410_for, frame_lights, period_light, run_bench
from spec import group_orders, prng, schedule
from spec.facts import TEST_DMD, TEST_DMD4, TEST_DMD4_400, TEST_DMD_400
from spec.registers import TIMED_NOTICE, PlaneOrder, ResetMode, Source, TriggerMode

DMD = TEST_DMD
#: RST_ACTIVE and settle scaled down (run-time parameters) so that frames simulate quickly.
FAST = {"t_rst_s": 20 / 200e6, "t_settle_s": 30 / 200e6}


def fast_plan(dmd=DMD, dclk=200e6, **kw):
    return schedule.plan(dmd, dclk, **FAST, **kw)


def model_frames(frames, images, dmd=DMD):
    """Model frames of (slot, depth), (slot, depth, ready) or (slot, depth, ready, sequence)."""
    out = []
    for slot, depth, *rest in frames:
        occ = None if images is None else \
            tuple(int(x) for x in bitplane.occupancy(images[slot], dmd.rows_per_block))
        out.append(schedule.Frame(slot, depth, occ, *rest[:1], *map(bool, rest[1:])))
    return out


def paced(p, frames, images):
    """Each frame offered just after the trigger that starts the one before it (so it is taken
    when that one ends), and the trigger pins as soon as each frame is ready."""
    offered, pins = [], []
    for slot, depth in frames:
        offered.append((slot, depth, pins[-1] + PIN_TO_STROBE + 4 if pins else 0))
        strobes = [t + PIN_TO_STROBE for t in pins]
        pins.append(next_ready(p, model_frames(offered, images), strobes) - PIN_TO_STROBE)
    return offered, pins


def next_ready(p, frames, strobes, dmd=DMD):
    """The first cycle a trigger is obeyed after the given strobes played out."""
    r = schedule.simulate(dmd, p, frames, strobes)
    return max(g.loaded_at for g in r.groups)


def same_commands(run, model):
    """Both command lists agree up to the end of the shorter run."""
    horizon = run.status["now"] - 2 * DMD.dclk_per_row
    got = [c for c in run.commands if c[0] < horizon]
    assert got == [c for c in model.decoded() if c[0] < horizon]
    return got


def check(p, frames, images, pins, name, *, extra=400, soft=(), sync_pins=(), early_pins=(),
          offered=None, dmd=DMD, store_words=1, model=None):
    """Run gateware and model; assert equal commands, counters, and exact light per frame.
    ``frames``: the frames expected on the DMD; ``offered``: what the store offers (default:
    the same); ``model``: the rule-checking DLPC410 model (default: as planned). The rule model
    logs no no-op rows (a 1080p clear's), the schedule model does."""
    offered = frames if offered is None else offered
    mframes = model_frames(offered, images, dmd)
    if p.trigger == TriggerMode.SOFTWARE:
        strobes = list(soft)
    else:
        strobes = [t + PIN_TO_STROBE for t in (sync_pins if p.trigger == TriggerMode.SYNC else pins)]
    dlpc410, model = model, schedule.simulate(dmd, p, mframes, strobes)
    end = max(c[0] for c in model.commands) + extra
    run = run_rig(dmd, p, offered, images, pins=pins, soft=soft, sync_pins=sync_pins,
                  early_pins=early_pins, cycles=end, name=name, store_words=store_words, model=dlpc410)
    assert run.commands == model.decoded()
    assert run.status["late"] == 0 == model.late
    assert run.status["underruns"] == 0
    assert run.status["overruns"] == model.overruns
    assert run.status["held"] == model.held
    assert run.status["triggers"] == len(model.accepted)
    assert run.status["early"] == len(early_pins)
    # the camera model on the rule model's mirror history, the window holding each frame
    run.lights = frame_lights(run.model, run.frames())
    for k, light in enumerate(run.lights):
        slot, depth = frames[min(k, len(frames) - 1)][:2]
        image = ramp_image(dmd, slot) if images is None else images[slot]
        assert np.array_equal(light, (image.astype(np.int64) >> (8 - depth)) * p.lsb), f"frame {k}"
    return run, model


@pytest.mark.verilog
@pytest.mark.parametrize("mode,strict,order", [
    (ResetMode.GLOBAL, True, PlaneOrder.MSB_FIRST),
    (ResetMode.GLOBAL, True, PlaneOrder.LSB_FIRST),
    (ResetMode.SINGLE, False, PlaneOrder.LSB_FIRST),
    (ResetMode.SINGLE, False, PlaneOrder.MSB_FIRST),
    (ResetMode.DUAL, True, PlaneOrder.MSB_FIRST),
    (ResetMode.QUAD, True, PlaneOrder.TABLE),
])
def test_every_level_exact(mode, strict, order, test_name):
    """Ramp image (every grey level in every block), one frame: commands equal, light exact."""
    p = fast_plan(reset_mode=mode, strict_rst=strict, order=order,
                  order_table=(3, 7, 0, 5, 1, 6, 2, 4)).params
    ready = next_ready(p, model_frames([(0, 8)], None), [])
    run, _ = check(p, [(0, 8)], None, [ready + 10], test_name)
    assert len(run.lights) == 1


@pytest.mark.verilog
@pytest.mark.parametrize("mode,tables,offsets", [
    (ResetMode.DUAL, ((2, 4, 0, 7, 5, 1, 6, 3), (6, 7, 1, 0, 3, 4, 5, 2)), (0, 312)),
    (ResetMode.SINGLE, ((0, 3, 7, 2, 1, 6, 5, 4), (5, 2, 0, 1, 4, 3, 7, 6), (4, 3, 5, 2, 6, 1, 0, 7),
                        (4, 3, 2, 6, 1, 7, 0, 5)), (0, 374, 262, 108)),
    (ResetMode.SINGLE, ((7, 6, 5, 4, 3, 2, 1, 0),) * 4, (0, 462, 154, 308)),
])
def test_each_group_plays_its_own_order_from_its_own_offset(mode, tables, offsets, test_name):
    """PlaneOrder.GROUPS: each group shows its planes in its own table's order, its first pulse
    its own offset after group 0's (offsets out of group order). Commands equal the model's,
    every grey level exact; each block's first state in each frame is the plane its group's
    table shows first, and the first pulses are the offsets apart (both written out here from
    the tables, not from the model)."""
    p = replace(fast_plan(reset_mode=mode).params, order=PlaneOrder.GROUPS, group_tables=tables,
                group_offsets=offsets)
    frames = [(0, 8), (1, 8)]
    offered, pins = paced(p, frames, None)
    run, model = check(p, frames, None, pins, test_name, offered=offered)
    assert len(run.lights) == len(frames)
    rpb, size = DMD.rows_per_block, DMD.blocks // len(tables)
    for (start, _), (slot, _) in zip(run.frames(), frames, strict=True):
        for b, history in enumerate(run.model.history):
            plane = (ramp_image(DMD, slot) >> tables[b // size][0]) & 1
            state = next(state for cycle, state in history if cycle >= start)
            assert np.array_equal(state, plane[b * rpb:(b + 1) * rpb]), f"block {b}"
    firsts = [min(at for at, h, *_ in model.pulses if h == g) for g in range(len(tables))]
    assert [f - min(firsts) for f in firsts] == [o - min(offsets) for o in offsets]


@pytest.mark.verilog
@pytest.mark.parametrize("mode,order,tables,shows", [
    (ResetMode.QUAD, PlaneOrder.TABLE, ((3, 7, 0, 5, 1, 6, 2, 4),), False),
    (ResetMode.QUAD, PlaneOrder.TABLE, ((2, 0, 3, 1, 7, 4, 6, 5),), True),
    (ResetMode.DUAL, PlaneOrder.GROUPS, ((3, 1, 0, 2, 7, 6, 5, 4), (7, 6, 5, 4, 3, 2, 1, 0)), False),
    (ResetMode.DUAL, PlaneOrder.GROUPS, ((3, 1, 0, 2, 7, 6, 5, 4), (3, 2, 1, 0, 7, 6, 5, 4)), True),
], ids=["table_drops", "table_shows", "groups_drop", "groups_show"])
def test_frame_its_order_cannot_show_is_dropped(mode, order, tables, shows, test_name):
    """A 4-plane frame between two 8-plane ones: shown when the first four entries of every
    table in force name planes 0..3, else dropped when offered and counted (never shown with
    planes beyond its own). Commands equal the model's, every grey level exact. In GROUPS the
    second group ends the 4-plane frame before the first: it takes the next frame itself, and
    the first follows it (a group that loaded the frame before again would tear the frame)."""
    p = fast_plan(reset_mode=mode).params
    if order == PlaneOrder.TABLE:
        p = replace(p, order=order, order_table=tables[0])
    else:
        p = replace(p, order=order, group_tables=tables, group_offsets=(0, 156))
    # each frame offered just after the trigger that starts the one before it
    offered, pins = [], []
    for slot, depth in [(0, 8), (1, 4), (0, 8)]:
        offered.append((slot, depth, pins[-1] + PIN_TO_STROBE + 4 if pins else 0))
        pins.append(next_ready(p, model_frames(offered, None), [t + PIN_TO_STROBE for t in pins]) - PIN_TO_STROBE)
    # dropped, the 4-plane frame leaves the first frame to show again at the second trigger
    shown = [(0, 8), (1, 4), (0, 8)] if shows else [(0, 8), (0, 8), (0, 8)]
    run, model = check(p, shown, None, pins, test_name, offered=offered, extra=32 * p.lsb)
    assert len(run.lights) == 3
    assert run.status["bad_frames"] == model.bad_frames == (0 if shows else 1)
    assert [(f.slot, f.depth) for f in model.shown] == (shown if shows else shown[::2])
    if order == PlaneOrder.GROUPS and shows:
        ends = [max(t for t, h, _, fi, _ in model.pulses if h == g and fi == 1) for g in range(2)]
        assert ends[1] < ends[0]


@pytest.mark.verilog
@pytest.mark.parametrize("mode,order,anchor,first", [
    (ResetMode.GLOBAL, PlaneOrder.LSB_FIRST, 7, (7, 1)),   # the MSB plane first (the paper's anchor)
    (ResetMode.DUAL, PlaneOrder.MSB_FIRST, 3, (4, 2)),
    (ResetMode.QUAD, PlaneOrder.TABLE, 7, (6, 5)),        # table (3, 5, 0, 4, 1, 2, 7, 6)
])
def test_anchor_starts_the_frame_at_its_plane(mode, order, anchor, first, test_name):
    """The anchor register: each frame starts at its position of the plane order, modulo its
    depth (an 8-plane frame, then a 6-plane one), and wraps round. Commands equal the model's,
    every grey level exact; the first state each block's mirrors take in a frame is the plane
    of weight ``2**first[k]`` (written out here from the order, not from the model)."""
    p = fast_plan(reset_mode=mode, order=order, order_table=(3, 5, 0, 4, 1, 2, 7, 6), anchor=anchor).params
    assert p.anchor == anchor
    frames = [(0, 8), (1, 6)]
    offered, pins = paced(p, frames, None)
    run, _ = check(p, frames, None, pins, test_name, offered=offered)
    assert len(run.lights) == len(frames)
    rpb = DMD.rows_per_block
    for (start, _), (slot, depth), e in zip(run.frames(), frames, first, strict=True):
        plane = (ramp_image(DMD, slot) >> (8 - depth + e)) & 1
        for b, history in enumerate(run.model.history):
            state = next(state for cycle, state in history if cycle >= start)
            assert np.array_equal(state, plane[b * rpb:(b + 1) * rpb]), f"block {b}"


@pytest.mark.verilog
@pytest.mark.parametrize("dmd,mode,order,store_words", [
    (TEST_DMD_400, ResetMode.GLOBAL, PlaneOrder.MSB_FIRST, 2),    # a row every row cycle
    (TEST_DMD_400, ResetMode.DUAL, PlaneOrder.LSB_FIRST, 1),      # the store paces the rows
    (TEST_DMD4_400, ResetMode.QUAD, PlaneOrder.MSB_FIRST, 2),     # four buses, two beats of two words
])
def test_two_beats_per_cycle(dmd, mode, order, store_words, test_name):
    """DCLK 400 MHz: two DCLK beats per cycle (a row cycle of half the cycles); a ramp frame then
    a random frame with empty blocks; commands equal the model's cycle for cycle, every grey
    level exact under the rule model, which reads two beats a cycle. With two words a transfer
    from the store, a row loads every row cycle."""
    rng = np.random.default_rng(6)
    noisy = rng.integers(0, 256, (dmd.rows, dmd.columns), dtype=np.uint8) & 0b10110111
    noisy[dmd.rows_per_block:2 * dmd.rows_per_block] = 0
    images = {0: ramp_image(dmd, 0), 1: noisy}
    plan = fast_plan(dmd, 400e6, reset_mode=mode, order=order, words_per_cycle=store_words)
    p = plan.params
    assert p.beats == 2
    row = dmd.dclk_per_row // 2
    assert p.row_period == (row if store_words * 64 >= dmd.bits_per_dclk * 2 else 2 * row)
    frames = [(0, 8), (1, 6)]
    offered, pins = [], []
    for slot, depth in frames:
        offered.append((slot, depth, pins[-1] + PIN_TO_STROBE + 4 if pins else 0))
        strobes = [t + PIN_TO_STROBE for t in pins]
        pins.append(next_ready(p, model_frames(offered, images, dmd), strobes, dmd) - PIN_TO_STROBE)
    run, _ = check(p, frames, images, pins, test_name, offered=offered, dmd=dmd, store_words=store_words)
    assert len(run.lights) == 2


@pytest.mark.verilog
def test_a_load_row_waits_for_a_dark_pulses_clears(test_name, monkeypatch):
    """A row of a load is not started when the oldest dark pulse's group's memory frees before
    the row would end: the clears go first (their deadline is the shortest plane's). Two groups
    in orders of their own at the settle path's LSB, whose clears have no cycle to spare, on a
    DMD of four cycles a row cycle: with the rule the model plays the frames with no pulse late,
    a row held back at least once, and the gateware's commands are the model's cycle for cycle,
    every level exact; without it (rows served as soon as they may) a pulse comes late."""
    dmd = TEST_DMD_400                                          # at 200 MHz: four cycles a row
    plan = fast_plan(dmd, reset_mode=ResetMode.DUAL, trigger_hold=True)
    p = plan.params
    R = schedule.row_cycles(dmd, 1)
    settle_path = p.t_rst + p.t_settle + 2 * dmd.clear_row_cycles * R      # two blocks a group
    p = replace(p, lsb=settle_path, dark_gap=p.hide, order=PlaneOrder.GROUPS,
                group_tables=((2, 4, 3, 7, 1, 5, 0, 6), (7, 5, 3, 1, 4, 6, 2, 0)), group_offsets=(0, 362))
    frames = [(0, 8), (1, 8)]
    offered, pins = [], []
    for slot, depth in frames:
        offered.append((slot, depth, pins[-1] + PIN_TO_STROBE + 4 if pins else 0))
        pins.append(next_ready(p, model_frames(offered, None, dmd), [t + PIN_TO_STROBE for t in pins], dmd)
                    - PIN_TO_STROBE)
    run, model = check(p, frames, None, pins, test_name, offered=offered, dmd=dmd)
    assert len(run.lights) == 2 and model.loads_held > 0
    strobes = [t + PIN_TO_STROBE for t in pins]
    monkeypatch.setattr(schedule._Model, "clears_soon", lambda self, t, length: False)
    assert schedule.simulate(dmd, p, model_frames(offered, None, dmd), strobes).late > 0


#: Group 0's offset in GROUPS that lets a trigger wait for its load only.
LEAD = schedule.trigger_lead(DMD)


@pytest.mark.verilog
@pytest.mark.parametrize("lead", [LEAD, 0], ids=["group_0_offset", "group_0_at_once"])
def test_groups_trigger_waits_for_group_0s_load_only(lead, test_name, monkeypatch):
    """In GROUPS, with group 0 offset, a trigger is obeyed once every group has made its frame's
    last dark pulse and group 0 is loaded: the other group's first load is still on the pins
    after the frame's first pulse, done by its own offset. Triggers faster than frames, held: no
    pulse late, commands the model's cycle for cycle, every level exact, and the frames come
    sooner than when the trigger waits for every group to be loaded. With group 0's offset 0 (no
    time for the bus to end a row under way) the trigger waits for every group: no group's rows
    between the frame's first pulses, in gateware and model alike."""
    tables, offsets = ((2, 4, 0, 7, 5, 1, 6, 3), (6, 7, 1, 0, 3, 4, 5, 2)), (lead, 312)
    p = replace(fast_plan(reset_mode=ResetMode.DUAL, trigger_hold=True).params, order=PlaneOrder.GROUPS,
                group_tables=tables, group_offsets=offsets)
    frames = [(0, 8)]
    first = next_ready(p, model_frames(frames, None), []) - PIN_TO_STROBE
    period = schedule.frame_period(DMD, p, schedule.Frame(0, 8))
    pins = [first + k * period // 3 for k in range(10)]
    run, model = check(p, frames, None, pins, test_name, extra=period)
    assert len(model.accepted) >= 3 and model.held >= 2
    # group 1's rows (its blocks') between a frame's first pulse and group 1's first pulse: its
    # first plane, loaded after the trigger
    rpb, size = DMD.rows_per_block, DMD.blocks // len(tables)
    pulses = [(t, blocks) for t, kind, blocks in run.commands if kind == "pulse"]
    rows = [t for t, kind, row in run.commands if kind == "row" and row // rpb // size == 1]
    firsts = {g: [] for g in range(2)}
    for g, table in enumerate(tables):
        mine = [t for t, blocks in pulses if g * size in blocks]
        per_frame = len(table) + sum((p.lsb << e) < p.hide for e in table) + ((p.lsb << table[-1]) >= p.hide)
        firsts[g] = mine[::per_frame]
    after_trigger = [sum(a < t < b for t in rows) for a, b in zip(firsts[0][1:], firsts[1][1:], strict=False)]
    assert after_trigger and all((n > 0) == bool(lead) for n in after_trigger), after_trigger
    if not lead:
        return
    # waiting for every group to be loaded, the same triggers start frames later
    starts = model.frame_starts
    monkeypatch.setattr(schedule._Model, "needs_loaded", lambda self: self.states)
    slower = schedule.simulate(DMD, p, model_frames(frames, None), [t + PIN_TO_STROBE for t in pins]).frame_starts
    assert starts[1] - starts[0] < slower[1] - slower[0]


@pytest.mark.verilog
@pytest.mark.parametrize("extra", [0, -2], ids=["trigger_lead", "a_notice_short"])
def test_groups_trigger_during_a_row(extra, test_name):
    """In GROUPS with group 0 offset, triggers come while the other group's first load runs, at
    many phases of its rows (eight triggers, three spacings), on a DMD of four cycles a row, at the
    settle path's LSB: with
    group 0's offset the trigger lead, gateware and model agree cycle for cycle and no pulse is
    late; two cycles less (a row cycle, without the bus's notice of the timed first pulse) the
    gateware starts a row the model holds back."""
    dmd = TEST_DMD_400                                          # at 200 MHz: four cycles a row
    lead = schedule.trigger_lead(dmd) + extra
    assert schedule.trigger_lead(dmd) == schedule.row_cycles(dmd) + TIMED_NOTICE
    p = fast_plan(dmd, reset_mode=ResetMode.DUAL, trigger_hold=True).params
    settle_path = p.t_rst + p.t_settle + 2 * dmd.clear_row_cycles * schedule.row_cycles(dmd)
    p = replace(p, lsb=settle_path, dark_gap=p.hide, order=PlaneOrder.GROUPS,
                group_tables=((2, 4, 3, 7, 1, 5, 0, 6), (7, 5, 3, 1, 4, 6, 2, 0)), group_offsets=(lead, 362 + lead))
    frames = model_frames([(0, 8)], None, dmd)
    first = next_ready(p, frames, [], dmd) - PIN_TO_STROBE
    period = schedule.frame_period(dmd, p, schedule.Frame(0, 8))
    same = []
    for k in range(3):
        pins = [first + j * (period // 3 + k) for j in range(8)]
        model = schedule.simulate(dmd, p, frames, [t + PIN_TO_STROBE for t in pins])
        run = run_rig(dmd, p, [(0, 8)], None, pins=pins, cycles=max(c[0] for c in model.commands) + period,
                      name=f"{test_name}_{k}")
        assert len(model.accepted) >= 3
        same.append(run.commands == model.decoded())
        if extra == 0:
            assert same[-1] and run.status["late"] == 0 == model.late
    assert all(same) == (extra == 0)


@pytest.mark.verilog
@pytest.mark.parametrize("strict", [True, False], ids=["rst_active_binds", "last_dark_pulse_binds"])
def test_groups_trigger_rule_to_the_cycle(strict, test_name):
    """In GROUPS, the first cycle a trigger is obeyed after a frame: once RST_ACTIVE allows group
    0's pulse (strict reading: after the other group's last dark pulse), or (loose) once that
    pulse has reached the frame control. A strobe a cycle sooner is an overrun, at that cycle it
    is obeyed: the gateware agrees with the model on both, commands cycle for cycle."""
    tables, offsets = ((2, 4, 0, 7, 5, 1, 6, 3), (6, 7, 1, 0, 3, 4, 5, 2)), (LEAD, 312)
    p = replace(fast_plan(reset_mode=ResetMode.DUAL).params, strict_rst=strict, order=PlaneOrder.GROUPS,
                group_tables=tables, group_offsets=offsets)
    frames = model_frames([(0, 8)], None)
    first = next_ready(p, frames, []) - PIN_TO_STROBE
    lone = schedule.simulate(DMD, p, frames, [first + PIN_TO_STROBE])
    end = max(at for at, g, kind, *_ in lone.pulses if kind == "dark")
    # the model's first cycle, searched from the last dark pulse on
    earliest = next(s for s in range(end, end + 200)
                    if len(schedule.simulate(DMD, p, frames, [first + PIN_TO_STROBE, s]).accepted) == 2)
    assert earliest == end + (p.t_rst if strict else schedule.END_TO_TRIGGER)
    for s, obeyed in ((earliest - 1, False), (earliest, True)):
        pins = [first, s - PIN_TO_STROBE]
        model = schedule.simulate(DMD, p, frames, [t + PIN_TO_STROBE for t in pins])
        run = run_rig(DMD, p, [(0, 8)], None, pins=pins, cycles=max(c[0] for c in model.commands) + 100,
                      name=f"{test_name}_{s - earliest}")
        assert run.commands == model.decoded()
        assert run.status["triggers"] == len(model.accepted) == 1 + obeyed
        assert run.status["overruns"] == model.overruns == 1 - obeyed
        assert run.status["late"] == 0 == model.late


@pytest.mark.verilog
def test_groups_trigger_after_a_reload_waits_for_every_group(test_name, monkeypatch):
    """A frame taken while the groups wait queues every group's first plane at once: the next
    trigger waits for all of them (not only group 0's), so no group's first pulse comes late.
    Four groups in orders of their own whose steady frames need no such wait: gateware and model
    agree cycle for cycle, no pulse late, both frames exact; the model waiting for group 0 alone
    after the reload makes pulses late."""
    tables = ((0, 3, 7, 2, 1, 6, 5, 4), (5, 2, 0, 1, 4, 3, 7, 6), (4, 3, 5, 2, 6, 1, 0, 7), (4, 3, 2, 6, 1, 7, 0, 5))
    p = replace(fast_plan(reset_mode=ResetMode.SINGLE, trigger_hold=True).params, order=PlaneOrder.GROUPS,
                group_tables=tables, group_offsets=tuple(LEAD + o for o in (0, 100, 200, 300)))
    first = next_ready(p, model_frames([(0, 8)], None), []) - PIN_TO_STROBE
    idle = waiting_after(p, [(0, 8)], [first + PIN_TO_STROBE]) + 30
    offered = [(0, 8, 0), (1, 8, idle)]
    pins = [first] + [idle + 10 + k * 50 for k in range(4)]
    run, model = check(p, [(0, 8), (1, 8)], None, pins, test_name, offered=offered)
    assert [f.slot for f in model.shown] == [0, 1] and len(model.accepted) == 2
    monkeypatch.setattr(schedule._Model, "steady", lambda self: True)
    assert schedule.simulate(DMD, p, model_frames(offered, None), [t + PIN_TO_STROBE for t in pins]).late > 0


@pytest.mark.verilog
def test_chained_groups_each_start_their_next_frame_as_they_end_their_own(test_name):
    """Chained frames of groups in orders of their own (the plan finder's, at TI's times): one
    trigger, then each group starts its next frame a dark gap after its own last dark pulse
    (read from the pins, written out here from the plane times), the commands the model's cycle
    for cycle, the rule model silent; over one period, from a frame's first pulse to the
    next's, every group's light is its frame's, every level exact."""
    plan, _ = group_orders.find(DMD, 200e6, ResetMode.SINGLE, seconds=3, chained=True, trigger_hold=True)
    p = plan.params
    frame = schedule.Frame(0, 8)
    ready = next_ready(p, [frame], [])
    cycles = ready + 4 * plan.frame_cycles
    model = schedule.simulate(DMD, p, [frame], [ready + PIN_TO_STROBE], until=cycles)
    run = run_rig(DMD, p, [(0, 8)], None, pins=[ready], cycles=cycles, name=test_name)
    commands = same_commands(run, model)
    assert run.status["late"] == 0 == model.late
    # each block's pulses on the pins: a frame is its group's table, each plane ``lsb << e``
    # long, a plane shorter than the hide threshold (and the last) then dark for the dark gap
    size = DMD.blocks // len(p.group_tables)
    starts = []
    for g, table in enumerate(p.group_tables):
        lengths = [p.lsb << e for e in table]
        darks = sum(n < p.hide or j == len(table) - 1 for j, n in enumerate(lengths))
        pulses = [t for t, kind, blocks in commands if kind == "pulse" and g * size in blocks]
        firsts = pulses[::len(table) + darks]
        periods = {b - a for a, b in zip(firsts, firsts[1:], strict=False)}
        assert len(firsts) >= 3 and periods == {sum(lengths) + darks * p.dark_gap}, f"group {g}"
        starts.append(firsts)
    light = period_light(run.model, starts[0][1], starts[0][2])
    assert np.array_equal(light, ramp_image(DMD, 0).astype(np.int64) * p.lsb)


@pytest.mark.verilog
def test_spread_phased_plan(test_name):
    """A phased plan with the groups spread apart (what the planner picks for single-block 8-bit
    PWM here, and for dual and single on the DLP7000): dark gaps off the LSB lattice, a stagger
    of several LSBs; commands equal, every level exact."""
    plan = fast_plan(reset_mode=ResetMode.SINGLE)
    p = plan.params
    assert "load queue order" in plan.binds
    assert p.dark_gap % p.lsb and p.stagger > 2 * p.lsb
    ready = next_ready(p, model_frames([(0, 8)], None), [])
    _run, model = check(p, [(0, 8)], None, [ready + 10], test_name)
    # some dark pulse's clear overtakes another group's plane load (between two of its rows)
    ops = [(kind, arg if kind == "clear" else arg // DMD.rows_per_block)
           for _t, kind, arg in model.commands if kind in ("row", "clear")]
    assert any(k == "clear" and a[0] == "row" == b[0] and a[1] == b[1] != c
               for a, (k, c), b in zip(ops, ops[1:], ops[2:], strict=False))


@pytest.mark.verilog
@pytest.mark.parametrize("mode,order", [
    (ResetMode.GLOBAL, PlaneOrder.MSB_FIRST),
    (ResetMode.QUAD, PlaneOrder.LSB_FIRST),      # groups of 4 blocks and of the fifth alone
])
def test_four_buses(mode, order, test_name):
    """A four-bus DMD (DLP9500-style: two words per DCLK on A-D, a clear plus two no-op rows):
    a ramp frame then a random 4-bit frame with empty blocks and planes (cleared, each clear
    followed by its no-op rows, no pulse of the block inside them); commands equal the model's,
    every level exact under the rule model. The store's one word per cycle sets a row every
    two row cycles."""
    dmd = TEST_DMD4
    rng = np.random.default_rng(4)
    noisy = rng.integers(0, 256, (dmd.rows, dmd.columns), dtype=np.uint8) & 0b11010110
    noisy[:dmd.rows_per_block] = 0
    images = {0: ramp_image(dmd, 0), 1: noisy}
    p = fast_plan(dmd, reset_mode=mode, order=order).params
    assert p.row_period == 2 * dmd.dclk_per_row
    frames = [(0, 8), (1, 4)]
    offered, pins = [], []
    for slot, depth in frames:
        offered.append((slot, depth, pins[-1] + PIN_TO_STROBE + 4 if pins else 0))
        strobes = [t + PIN_TO_STROBE for t in pins]
        pins.append(next_ready(p, model_frames(offered, images, dmd), strobes, dmd) - PIN_TO_STROBE)
    run, model = check(p, frames, images, pins, test_name, offered=offered, dmd=dmd)
    assert len(run.lights) == 2
    assert any(k == "noop" for _t, k, _a in model.commands)


@pytest.mark.verilog
def test_random_images_every_depth_with_empty_blocks(seed, test_name):
    """Random images (a fresh seed each run) at bit depths 1..8 back to back (triggered as soon as
    ready); one slot has empty blocks and empty planes, cleared instead of loaded."""
    rng = np.random.default_rng(seed)
    a = rng.integers(0, 256, (DMD.rows, DMD.columns), dtype=np.uint8)
    b = rng.integers(0, 256, (DMD.rows, DMD.columns), dtype=np.uint8) & 0b10110101
    b[:DMD.rows_per_block] = 0
    b[2 * DMD.rows_per_block:3 * DMD.rows_per_block] &= 0x0f
    images = {0: a, 1: b}
    frames = [(k % 2, depth) for k, depth in enumerate(range(1, 9))]
    p = fast_plan(reset_mode=ResetMode.DUAL).params
    offered, pins = paced(p, frames, images)
    run, model = check(p, frames, images, pins, test_name, offered=offered)
    assert len(run.lights) == len(frames)
    # each slot is handed back when every group has moved to the next frame's slot
    assert [s for _t, s in run.releases] == [k % 2 for k in range(len(frames) - 1)]
    assert any(k == "clear" for _t, k, _a in model.commands[:200])


@pytest.mark.verilog
def test_extremes_all_dark_all_bright(test_name):
    """All-0 (every block empty: clears only) and all-255 (every block full), depth 8 and 1."""
    shape = (DMD.rows, DMD.columns)
    images = {0: np.zeros(shape, np.uint8), 1: np.full(shape, 255, np.uint8)}
    frames = [(0, 8), (1, 8), (0, 1), (1, 1)]
    p = fast_plan().params
    offered, pins = paced(p, frames, images)
    run, model = check(p, frames, images, pins, test_name, offered=offered)
    assert len(run.lights) == 4
    first_rows = [k for _t, k, _a in model.commands[:DMD.blocks]]
    assert first_rows == ["clear"] * DMD.blocks


@pytest.mark.verilog
def test_triggers(test_name):
    """Before init ends, early, during a frame, a burst faster than frames, one cycle before the
    next frame is ready and exactly when it is: counted right, never half-obeyed."""
    p = fast_plan().params
    first = next_ready(p, model_frames([(0, 4)], None), []) - PIN_TO_STROBE
    after_first = first + PIN_TO_STROBE + 4
    # two frames with bad depths, dropped; each good frame offered while the one before plays
    frames = [(0, 4, 0), (1, 0, after_first), (1, 4, after_first), (1, 9, after_first)]
    second = next_ready(p, model_frames(frames, None), [first + PIN_TO_STROBE]) - PIN_TO_STROBE
    frames.append((0, 4, second + 7 + PIN_TO_STROBE + 4))
    mframes = model_frames(frames, None)
    third = next_ready(p, mframes, [first + PIN_TO_STROBE, second + 7 + PIN_TO_STROBE]) - PIN_TO_STROBE
    pins = [20,                                  # before the first plane is loaded: overrun
            first, first + 300, first + 310, first + 320,   # a frame plays: burst of overruns
            second - 1,                          # one cycle early: overrun
            second + 7,                          # accepted (edge after the early one's pulse)
            third]                               # exactly when ready: accepted
    run, model = check(p, [f[:2] for f in frames if 1 <= f[1] <= 8], None, pins, test_name,
                       early_pins=(3, 9), offered=frames)
    assert model.overruns == 5 and len(model.accepted) == 3
    assert run.status["frames"] == 3 and run.status["bad_frames"] == model.bad_frames == 2


@pytest.mark.verilog
@pytest.mark.parametrize("mode", [ResetMode.GLOBAL, ResetMode.DUAL])
def test_early_triggers_held(mode, test_name):
    """With ``trigger_hold``, a trigger during a frame is held and obeyed on the first cycle
    every group is ready (the frame after it starts at once), a second one meanwhile is an
    overrun, and a trigger while a newer frame's first plane reloads is held too: no frame is
    lost. Triggers come faster than frames: the frames play back to back."""
    plan = fast_plan(reset_mode=mode, depth=4)
    p = plan.params
    p.trigger_hold = True
    first = next_ready(p, model_frames([(0, 4)], None), []) - PIN_TO_STROBE
    frames = [(0, 4, 0), (1, 4, first + PIN_TO_STROBE + 4), (0, 3, first + PIN_TO_STROBE + 4)]
    # triggers at 0.6 of the frame period: each one early, held, a burst's second an overrun
    period = plan.frame_cycles
    pins = [first + round(k * 0.6 * period) for k in range(5)] + [first + round(1.2 * period) + 30]
    # the frames shown, in order (a frame repeats when no newer one is there at its end)
    result = schedule.simulate(DMD, p, model_frames(frames, None), [t + PIN_TO_STROBE for t in pins])
    fi = {t: f for t, g, kind, f, _e in result.pulses if g == 0}
    shown = [(result.shown[fi[t]].slot, result.shown[fi[t]].depth) for t in result.frame_starts]
    run, model = check(p, shown, None, pins, test_name, offered=frames, extra=period)
    assert model.held >= 2 and model.overruns >= 1 and len(model.accepted) >= 3
    # a held trigger is obeyed the cycle every group is ready: frames back to back
    starts = model.frame_starts
    assert all(b > a for a, b in zip(starts, starts[1:], strict=False))


@pytest.mark.verilog
def test_stored_sequence_frames_wait_their_turn(test_name):
    """Frames of a stored sequence offered while the first waits for its trigger do not replace
    it (a newer streamed frame would): each trigger shows the next frame in order."""
    rng = np.random.default_rng(9)
    images = {s: rng.integers(0, 256, (DMD.rows, DMD.columns), dtype=np.uint8) for s in range(2)}
    p = fast_plan(depth=4).params
    frames = [(0, 4, 0, 1), (1, 4, 0, 1), (0, 4, 0, 1)]
    first = next_ready(p, model_frames(frames[:1], images), []) + 200
    period = schedule.plan(DMD, 200e6, **FAST, depth=4).frame_cycles
    pins = [first + k * (period + 300) for k in range(3)]
    run, model = check(p, [(0, 4), (1, 4), (0, 4)], images, pins, test_name, offered=frames)
    assert [f.slot for f in model.shown] == [0, 1, 0] and len(run.lights) == 3


@pytest.mark.verilog
@pytest.mark.parametrize("offset,width", [(100, 7), (0, 1)])     # (0, 1): the power-up values
def test_sync_out_and_camera(offset, width, test_name):
    p = fast_plan().params
    p.camera_offset, p.camera_width = offset, width
    ready = next_ready(p, model_frames([(0, 8)], None), [])
    run, model = check(p, [(0, 8)], None, [ready], test_name)
    # both leave with the pulses' commands, DECISION_TO_PINS after their decisions (sync out is
    # logged on the cycle its register is set)
    pulses = [t for t, k, _a in model.commands if k == "pulse"]
    pins = schedule.DECISION_TO_PINS
    assert run.sync_out == [(pulses[0] + pins - 1, 1), (pulses[-1] + pins - 1, 0)]
    assert run.camera_out == [(pulses[0] + pins + offset, 1), (pulses[0] + pins + offset + width, 0)]


@pytest.mark.verilog
@pytest.mark.parametrize("mode", [TriggerMode.PERIODIC, TriggerMode.SOFTWARE, TriggerMode.SYNC])
def test_trigger_modes(mode, test_name):
    p = fast_plan().params
    p.trigger = mode
    ready = next_ready(p, model_frames([(0, 2)], None), [])
    frames = [(0, 2), (1, 2, ready + 100)]
    if mode == TriggerMode.PERIODIC:
        p.period = ready + 1
        strobes = [k * p.period - 1 for k in range(1, 7)]
        model = schedule.simulate(DMD, p, model_frames(frames, None), strobes, until=strobes[-1] - 4)
        run = run_rig(DMD, p, frames, None, cycles=strobes[-1] - 4, name=test_name)
        same_commands(run, model)
        assert run.status["triggers"] == len(model.accepted) >= 2
        assert run.status["overruns"] == model.overruns >= 1
    elif mode == TriggerMode.SOFTWARE:
        run, model = check(p, frames, None, [], test_name, soft=[ready, ready + 40], offered=frames)
        assert run.status["triggers"] == 1 and run.status["overruns"] == 1
    else:
        run, model = check(p, frames, None, [ready], test_name, sync_pins=[ready + 50], offered=frames)
        assert run.status["triggers"] == 1    # the TTL pin is ignored in sync mode


@pytest.mark.verilog
@pytest.mark.parametrize("short", [True, False])
def test_periodic_trigger_faster_than_the_frames_is_counted(short, test_name):
    """A periodic trigger every 2 LSB under frames of 2 planes (3 LSB): every frame started is
    counted (``period_short``) and the strobes that come while it plays are overruns; at the
    plan's frame period neither."""
    plan = fast_plan(depth=2)
    p = plan.params
    p.trigger = TriggerMode.PERIODIC
    ready = next_ready(p, model_frames([(0, 2)], None), [])
    p.period = 2 * p.lsb if short else plan.trigger_cycles
    strobes = [k * p.period - 1 for k in range(1, (ready + 4 * plan.frame_cycles) // p.period + 1)]
    model = schedule.simulate(DMD, p, model_frames([(0, 2)], None), strobes, until=strobes[-1] - 4)
    run = run_rig(DMD, p, [(0, 2)], None, cycles=strobes[-1] - 4, name=test_name)
    same_commands(run, model)
    assert run.status["frames"] >= 2
    assert run.status["period_short"] == (run.status["frames"] if short else 0)
    assert run.status["overruns"] == model.overruns and (model.overruns > 0) == short


@pytest.mark.verilog
@pytest.mark.parametrize("dmd", [DMD, TEST_DMD4], ids=["two_buses", "four_buses"])
def test_binary_prng_chain(dmd, test_name):
    """1-bit Bernoulli frames back to back at the bus limit: the patterns the host rebuilds
    from the seed are exactly the ones shown (four buses: two words of the sequence a cycle)."""
    p = fast_plan(dmd, depth=1, chain=True, source=Source.PRNG, reset_mode=ResetMode.SINGLE,
                  strict_rst=False).params
    ready = next_ready(p, [schedule.Frame(0, 1)], [], dmd)
    model = schedule.simulate(dmd, p, [], [ready + PIN_TO_STROBE], until=ready + 6 * p.lsb)
    run = run_rig(dmd, p, [], None, pins=[ready], cycles=ready + 6 * p.lsb, name=test_name, seed=0x1234)
    commands = same_commands(run, model)
    shown = prng.shown_patterns(dmd, commands, 0x1234)
    pulses = [t for t, k, _a in commands if k == "pulse"]
    assert len(pulses) >= 8
    # the frame period is the bus limit: one full load per pattern
    assert p.lsb == p.stagger * dmd.blocks
    # the decoder's mirrors hold the last shown pattern, the host's rebuild of it
    assert np.array_equal(run.model.mirrors, shown[-1])
    assert not np.array_equal(shown[-1], prng.shown_patterns(dmd, commands, 0)[-1])


@pytest.mark.verilog
@pytest.mark.parametrize("ecp2_cycles", [4, 60])
def test_init_driven_by_the_model(ecp2_cycles, test_name):
    """ECP2_FINISHED and INIT_ACTIVE as the rule model times them (ECP2_FINISHED before ARSTZ's
    initialisation ends, and long after it; driven by the responder with the model's cycle
    counts, which the model checks on every cycle); the model checks the training pattern on
    every data pin and that no command comes meanwhile; the first DVALID comes 64 to 80 clocks
    after INIT_ACTIVE falls, then a frame plays legally."""
    p = fast_plan(depth=2).params
    model = dlpc410_for(DMD, p, ecp2_cycles=ecp2_cycles)
    ready = next_ready(p, model_frames([(0, 2)], None), [])
    run = run_rig(DMD, p, [(0, 2)], pins=[ready], cycles=ready + 3 * p.lsb + 400, name=test_name, model=model)
    assert model.init_end == max(ecp2_cycles, 0) + INIT_CYCLES
    first = model.log[0].cycle
    assert 64 <= first - model.init_end < 80
    assert run.status["frames"] == 1 and [k for _t, k, _a in run.commands].count("pulse") == 4


def test_init_waits_for_ecp2(test_name):
    """INIT_ACTIVE low before ECP2_FINISHED rises (not yet valid, DLPC910): no command, the
    sequencer keeps sending the training pattern until ECP2_FINISHED is high."""
    from gateware.dlpc410.interface import BlockMode, RowMode
    from gateware.registers import Registers
    from sim.harness.amaranth_sim import simulate
    from sim.tb.plane_source import SequencerBench

    dut = SequencerBench(DMD, [(0, 8)])
    p = fast_plan().params

    async def bench(ctx):
        ctx.set(dut.regs, Registers.const(p.registers(DMD)))
        ctx.set(dut.pins.ecp2_finished, 0)
        ctx.set(dut.pins.init_active, 0)
        for _ in range(200):
            await ctx.tick()
            assert ctx.get(dut.status.now) == 0
            assert ctx.get(dut.pins.rowmd) == RowMode.NOOP and ctx.get(dut.pins.blkmd) == BlockMode.NOOP
        ctx.set(dut.pins.ecp2_finished, 1)
        for _ in range(10):
            await ctx.tick()
        assert ctx.get(dut.status.now) > 0

    simulate(dut, [bench], name=test_name, clocks={"sync": 200e6})


@pytest.mark.verilog
def test_rig_runs_as_the_amaranth_bench(test_name):
    """One short scenario (a trigger before initialisation ends, two frames from two slots paced
    by the pin, a camera pulse) in the Amaranth simulator (the model stepped every cycle) and on
    the rig (the trace replayed): the same commands, both the schedule model's, and the same
    time base, counters, sync and camera edges and releases."""
    p = fast_plan(depth=2).params
    p.camera_offset, p.camera_width = 20, 5
    offered, pins = paced(p, [(0, 2), (1, 2)], None)
    model = schedule.simulate(DMD, p, model_frames(offered, None), [t + PIN_TO_STROBE for t in pins])
    given = {"pins": pins, "early_pins": (5,), "cycles": max(c[0] for c in model.commands) + 100}
    bench = run_bench(DMD, p, offered, None, name=f"{test_name}_amaranth", **given)
    rig = run_rig(DMD, p, offered, None, name=test_name, **given)
    assert bench.commands == model.decoded() == rig.commands
    for what in ("shift", "status", "sync_out", "camera_out", "releases"):
        assert getattr(rig, what) == getattr(bench, what), what
    assert bench.releases == [(bench.releases[0][0], 0)] and len(bench.camera_out) == 4
    assert bench.status["early"] == 1 and bench.status["triggers"] == 2


@pytest.mark.verilog
def test_rule_model_catches_too_short_settle_time(test_name):
    """Parameters planned for a shorter settle time than the controller needs: the rule model
    stops the run at the first write into a settling block (it is wired in, not a bystander)."""
    p = fast_plan(depth=2).params
    model = dlpc410_for(DMD, p)
    model.settle_cycles = p.t_settle + 200
    ready = next_ready(p, model_frames([(0, 2)], None), [])
    with pytest.raises(RuleBreak) as e:
        run_rig(DMD, p, [(0, 2)], pins=[ready], cycles=ready + 3 * p.lsb, name=test_name, model=model)
    assert e.value.rule == RULES["settle"]


@pytest.mark.verilog
def test_rst_active_as_planned_counts_nothing(test_name):
    """RST_ACTIVE as long as planned: the settle taken from its fall changes nothing (commands
    equal to the schedule model's, every level exact) and nothing is counted."""
    p = fast_plan(depth=3).params
    first = next_ready(p, model_frames([(0, 3)], None), []) - PIN_TO_STROBE
    run, _model = check(p, [(0, 3)], None, [first], test_name)
    assert run.status["rst_late"] == 0 and run.status["rst_faults"] == 0
    # the longest RST_ACTIVE, from the decision (the pins show the pulse DECISION_TO_PINS later)
    # to the fall (the cycle after the last high one): the planned t_rst less its two spare cycles
    assert run.status["rst_longest"] == dlpc410_for(DMD, p).rst_active_cycles + schedule.DECISION_TO_PINS + 1 \
        == p.t_rst - 2


@pytest.mark.verilog
def test_rst_active_longer_than_planned(test_name):
    """A controller that holds RST_ACTIVE 20 cycles longer than planned: the sequencer makes
    no pulse while it is high and changes no block's memory until ``t_settle`` after it fell
    (the rule model, checking every cycle, stays silent), and counts each late fall; the frame
    is played whole, its late pulses counted."""
    p = fast_plan(depth=3).params
    model = dlpc410_for(DMD, p)
    model.rst_active_cycles += 20
    first = next_ready(p, model_frames([(0, 3)], None), []) - PIN_TO_STROBE
    planned = schedule.simulate(DMD, p, model_frames([(0, 3)], None), [first + PIN_TO_STROBE])
    want = len([t for t, k, _a in planned.commands if k == "pulse"])
    run = run_rig(DMD, p, [(0, 3)], pins=[first], cycles=first + 60 * p.lsb, name=test_name, model=model)
    pulses = [c for c in run.model.log if c.kind == "pulse"]
    assert len(pulses) == want
    assert run.status["rst_late"] == want and run.status["rst_faults"] == 0
    assert run.status["late"] > 0
    assert run.status["rst_longest"] == model.rst_active_cycles + schedule.DECISION_TO_PINS + 1
    # planned with the time the projector measured, the same controller keeps every plane on
    # time: every level exact, commands equal to the schedule model's, nothing late
    calibrated = fast_plan(depth=3, t_rst_cycles=run.status["rst_longest"]).params
    same = dlpc410_for(DMD, calibrated)
    same.rst_active_cycles = model.rst_active_cycles
    first = next_ready(calibrated, model_frames([(0, 3)], None), []) - PIN_TO_STROBE
    again, _model = check(calibrated, [(0, 3)], None, [first], f"{test_name}-calibrated", model=same)
    assert again.status["rst_late"] == 0 and again.status["rst_faults"] == 0


@pytest.mark.verilog
def test_rst_active_stuck_high(test_name):
    """RST_ACTIVE stuck high after each pulse (far beyond ``t_rst + t_settle``): the fault is
    counted once a pulse, no pulse is made and no memory changes while it is high (the rule model stays
    silent); when it falls at last, the frame goes on."""
    p = fast_plan(depth=2).params
    model = dlpc410_for(DMD, p)
    model.rst_active_cycles = p.t_rst + 4 * p.t_settle
    ready = next_ready(p, model_frames([(0, 2)], None), [])
    planned = schedule.simulate(DMD, p, model_frames([(0, 2)], None), [ready])
    want = len([t for t, k, _a in planned.commands if k == "pulse"])
    run = run_rig(DMD, p, [(0, 2)], pins=[ready - PIN_TO_STROBE],
                  cycles=ready + 2 * want * (p.t_rst + 4 * p.t_settle), name=test_name, model=model)
    pulses = [c for c in run.model.log if c.kind == "pulse"]
    assert len(pulses) == want
    assert run.status["rst_faults"] == want


@pytest.mark.verilog
def test_binary_chain_from_memory(test_name):
    """1-bit frames from the store back to back: each pattern is loaded behind the one shown."""
    rng = np.random.default_rng(9)
    images = {s: rng.integers(0, 256, (DMD.rows, DMD.columns), dtype=np.uint8) for s in (0, 1)}
    frames = [(0, 1), (1, 1), (0, 1), (1, 1)]
    p = fast_plan(depth=1, chain=True).params
    mframes = model_frames(frames, images)
    ready = next_ready(p, mframes, [])
    until = ready + 5 * p.lsb
    model = schedule.simulate(DMD, p, mframes, [ready + PIN_TO_STROBE], until=until)
    run = run_rig(DMD, p, frames, images, pins=[ready], cycles=until, name=test_name)
    commands = same_commands(run, model)
    pulses = [t for t, k, _a in commands if k == "pulse"]
    assert len(pulses) == 5 and set(np.diff(pulses)) == {p.lsb}
    # the last pattern shown: frame 4 (slot 1) while it lasts, then the last frame repeats
    assert np.array_equal(run.model.mirrors, images[1] >> 7)
    assert run.status["frames"] == 5 and run.sync_out == [(pulses[0] + schedule.DECISION_TO_PINS - 1, 1)]


@pytest.mark.verilog
def test_too_short_lsb_is_counted_late(test_name):
    """A least significant plane shorter than the settle rule allows: the pulses come late
    (never while RST_ACTIVE is high, never into a settling block), both gateware and model
    count them, and the command streams still agree."""
    p = fast_plan(depth=3).params
    p.lsb -= 16
    frames = [(0, 3)]
    ready = next_ready(p, model_frames(frames, None), [])
    model = schedule.simulate(DMD, p, model_frames(frames, None), [ready + PIN_TO_STROBE])
    run = run_rig(DMD, p, frames, None, pins=[ready], cycles=model.commands[-1][0] + 50, name=test_name)
    same_commands(run, model)
    assert run.status["late"] == model.late > 0


def waiting_after(p, frames, strobes):
    """The cycle from which every group waits loaded again after the given strobes played out
    (the frame shown repeated, nothing newer offered)."""
    return next_ready(p, model_frames(frames, None), strobes)


@pytest.mark.verilog
@pytest.mark.parametrize("mode,lead", [(ResetMode.GLOBAL, 16), (ResetMode.DUAL, 75)])
def test_frame_offered_while_waiting_is_shown_next(mode, lead, test_name):
    """Frame 1 completes while the projector waits (frame 0 shown, its repeat preloaded): its
    first plane is loaded ``reload_lead`` cycles later (a run-time register: 16, and 75 for a
    slower store) and the next trigger shows it, not frame 0 again; with nothing newer offered,
    the next trigger repeats frame 1."""
    p = fast_plan(depth=3, reset_mode=mode).params
    p.reload_lead = lead
    first = next_ready(p, model_frames([(0, 3)], None), []) - PIN_TO_STROBE
    idle = waiting_after(p, [(0, 3)], [first + PIN_TO_STROBE]) + 30
    offered = [(0, 3, 0), (1, 3, idle)]
    second = next_ready(p, model_frames(offered, None), [first + PIN_TO_STROBE]) - PIN_TO_STROBE
    third = waiting_after(p, offered, [first + PIN_TO_STROBE, second + PIN_TO_STROBE]) - PIN_TO_STROBE
    run, model = check(p, [(0, 3), (1, 3), (1, 3)], None, [first, second, third], test_name,
                       offered=offered)
    assert [f.slot for f in model.shown] == [0, 1] and len(run.lights) == 3
    assert model.overruns == 0 and len(model.accepted) == 3
    # the reload: every group's first plane again, from slot 1, after the frame was offered
    reloads = [t for t, k, _a in model.commands if k != "pulse" and idle < t < second]
    assert reloads and lead <= reloads[0] - idle <= lead + 2
    assert [s for _t, s in run.releases] == [0]


@pytest.mark.verilog
def test_trigger_during_reload_is_an_overrun(test_name):
    """A trigger while the newer frame's first plane is being loaded is ignored and counted:
    nothing mixed is shown; the next trigger shows the newer frame whole."""
    p = fast_plan(depth=3).params
    first = next_ready(p, model_frames([(0, 3)], None), []) - PIN_TO_STROBE
    idle = waiting_after(p, [(0, 3)], [first + PIN_TO_STROBE]) + 30
    offered = [(0, 3, 0), (1, 3, idle)]
    # (the first strobe on the cycle the sequencer sees the newer frame)
    early = [idle + schedule.OFFER_LAG - PIN_TO_STROBE, idle + p.reload_lead + 10 - PIN_TO_STROBE]
    strobes = [first + PIN_TO_STROBE] + [t + PIN_TO_STROBE for t in early]
    second = next_ready(p, model_frames(offered, None), strobes) - PIN_TO_STROBE
    run, model = check(p, [(0, 3), (1, 3)], None, [first, *early, second], test_name, offered=offered)
    assert model.overruns == 2 and run.status["triggers"] == 2
    assert len(run.lights) == 2 and [f.slot for f in model.shown] == [0, 1]


@pytest.mark.verilog
@pytest.mark.parametrize("mode,after", [
    (ResetMode.GLOBAL, 1),       # inside the settle time: the stale rows are asked, not loaded
    (ResetMode.DUAL, 1),         # group 1 still plays: taken when it ends, its load abandoned
    (ResetMode.GLOBAL, 90),      # half-way through the stale load on the bus
])
def test_frame_offered_late_in_a_frame_abandons_the_stale_preload(mode, after, test_name):
    """Frame 1 completes ``after`` cycles after group 0's last pulse of frame 0 (too late to be
    taken there): frame 0's first plane, being preloaded again, is abandoned as soon as no group
    plays: the row cycle on the bus ends, the words asked for are discarded, frame 1's first
    plane is loaded (no sooner than each group's settle time allows) and the next trigger shows
    it whole. A trigger while the stale load is being flushed is an overrun."""
    p = fast_plan(depth=3, reset_mode=mode).params
    first = next_ready(p, model_frames([(0, 3)], None), []) - PIN_TO_STROBE
    alone = schedule.simulate(DMD, p, model_frames([(0, 3)], None), [first + PIN_TO_STROBE])
    last_pulse = max(t for t, g, _k, _f, _e in alone.pulses if g == 0)
    end = max(t for t, *_rest in alone.pulses)
    ready = last_pulse + after
    offered = [(0, 3, 0), (1, 3, ready)]
    flushing = [max(ready, end) + 20 - PIN_TO_STROBE]
    strobes = [first + PIN_TO_STROBE, flushing[0] + PIN_TO_STROBE]
    second = next_ready(p, model_frames(offered, None), strobes) - PIN_TO_STROBE
    run, model = check(p, [(0, 3), (1, 3)], None, [first, *flushing, second], test_name, offered=offered)
    assert [f.slot for f in model.shown] == [0, 1] and model.overruns == 1
    assert [s for _t, s in run.releases] == [0]
    # the stale repeat was cut: fewer rows than a plane loaded before frame 1's first row
    taken = max(ready + schedule.OFFER_LAG, end + 1)
    wait = schedule.flush_rows(DMD) * p.row_period
    new_start = schedule.even(max(taken + p.reload_lead + wait, end + p.t_rst + p.t_settle))
    loads = [t for t, k, _a in model.commands if k != "pulse" and t >= last_pulse]
    assert new_start in loads and new_start - 2 not in loads
    stale = [t for t in loads if t < new_start]
    if mode == ResetMode.GLOBAL:   # the rows of the stale load on the bus before it was taken
        assert len(stale) == max(0, (taken - (last_pulse + p.t_rst + p.t_settle)) // p.row_period + 1)
    else:                          # group 0 had begun loading while group 1 still played
        assert 0 < len(stale) < DMD.rows
    # the whole reload took less than a repeat followed by a reload
    assert second + PIN_TO_STROBE < waiting_after(p, [(0, 3)], [first + PIN_TO_STROBE]) + DMD.rows * p.row_period


@pytest.mark.verilog
@pytest.mark.parametrize("ecp2_low,mode", [(0, ResetMode.GLOBAL), (60, ResetMode.GLOBAL), (0, ResetMode.SINGLE)])
def test_controller_restart_mid_frame(ecp2_low, mode, test_name):
    """The controller initialises again in the middle of a frame (INIT_ACTIVE high again; with
    ``ecp2_low``, ECP2_FINISHED low for its first cycles too: it was reconfigured): the DMD's
    memory and mirrors are lost. Once the sequencer has seen it (a synchroniser later) it makes no
    command and sends the training pattern while INIT_ACTIVE is high, keeps DVALID low for
    ``init_to_dvalid`` clocks after it falls (the rule model checks every cycle), counts the
    restart, abandons the frame and starts over from every group's first plane; the next trigger
    shows the frame whole, every level exact. Single-block groups: the restart comes while a dark
    pulse's clears wait in their own queue (they are dropped with the loads)."""
    p = fast_plan(depth=3, reset_mode=mode).params
    ready = next_ready(p, model_frames([(0, 3)], None), [])
    period = next_ready(p, model_frames([(0, 3)], None), [ready]) - ready
    if mode == ResetMode.GLOBAL:
        # mid-frame: the first plane shown, the second being loaded (model cycles)
        restart_at = INIT_CYCLES + 8 + ready + 2 * p.lsb
    else:
        # a group's pulse whose next is dark, RST_ACTIVE still high: its clears are queued
        pulses = schedule.simulate(DMD, p, model_frames([(0, 3)], None), [ready]).pulses
        dark_at, g = next((t, g) for t, g, kind, *_ in pulses if kind == "dark")
        freed = max(t for t, h, *_ in pulses if h == g and t < dark_at)
        restart_at = INIT_CYCLES + 8 + freed + p.t_rst // 2
    model = dlpc410_for(DMD, p)
    model.restart_at, model.restart_cycles, model.restart_ecp2_cycles = restart_at, 300, ecp2_low
    pins = [ready - PIN_TO_STROBE, ready + 2 * period]
    run = run_rig(DMD, p, [(0, 3)], pins=pins, cycles=ready + 4 * period, name=test_name, model=model)
    assert run.status["restarts"] == 1
    assert run.status["frames"] == 2 and run.status["triggers"] == 2
    end = restart_at + model.restart_cycles
    pulses = [c.cycle for c in model.log if c.kind == "pulse"]
    before = [t for t in pulses if t < restart_at]
    after = [t for t in pulses if t >= restart_at]
    assert 0 < len(before) < len(after)
    assert not [c for c in model.log if restart_at + model.restart_grace_cycles <= c.cycle < end]
    assert min(c.cycle for c in model.log if c.cycle >= end) >= end + model.init_to_dvalid_clocks
    lights = frame_lights(model, run.frames())
    assert len(lights) == 2
    assert np.array_equal(lights[-1], (ramp_image(DMD, 0).astype(np.int64) >> 5) * p.lsb)
    assert not np.array_equal(lights[0], lights[-1])


@pytest.mark.verilog
def test_periodic_trigger_at_the_frame_rate_loses_none(seed, test_name):
    """A periodic trigger at the plan's shortest trigger period (``trigger_cycles``: the
    back-to-back frame period, and a cycle for strobes on odd cycles), trigger_hold on, and newer frames
    completing at random phases of it (a fresh seed each run, in the messages): no trigger is
    lost, held or delayed. A newer frame that cannot be reloaded before the next trigger is due
    waits for the trigger after (without that rule the same run loses triggers: checked on the
    schedule model). Commands equal the schedule model's; every frame shown is exact."""
    rng = np.random.default_rng(seed)
    plan = fast_plan(depth=3)
    p = plan.params
    p.trigger, p.trigger_hold, p.period = TriggerMode.PERIODIC, True, plan.trigger_cycles
    n = 14
    strobes = [k * p.period - 1 for k in range(1, n)]
    offered = [(0, 3, 0)] + [(k % 2, 3, int((k + rng.random()) * p.period)) for k in range(1, n)]
    # and one frame that completes just before a trigger, too late to be reloaded for it
    offered[3] = (1, 3, strobes[3] - schedule.reload_bound(DMD, p) // 2)
    until = strobes[-1] + p.period // 2
    frames = model_frames(offered, None)
    model = schedule.simulate(DMD, p, frames, strobes, until=until)
    assert model.overruns == 0 and model.held == 0 and len(model.accepted) == len(strobes), seed
    assert model.accepted == strobes, f"seed {seed}: a trigger was delayed"
    unguarded = schedule._Model(DMD, p, frames, strobes)
    unguarded.fits = lambda t: True
    lost = unguarded.run(until=until)
    assert lost.held + lost.overruns > 0, f"seed {seed}: the run does not need the rule"
    run = run_rig(DMD, p, offered, None, cycles=until, name=test_name)
    same_commands(run, model)
    assert run.status["overruns"] == 0 and run.status["held"] == 0, seed
    assert run.status["triggers"] == len(strobes), seed
    fi = {t: f for t, g, kind, f, _e in model.pulses if g == 0}
    shown = [model.shown[fi[t]] for t in model.frame_starts]
    lights = frame_lights(run.model, run.frames())
    assert len(lights) >= len(strobes) - 1, seed
    for k, light in enumerate(lights[:len(shown)]):
        want = (ramp_image(DMD, shown[k].slot).astype(np.int64) >> (8 - shown[k].depth)) * p.lsb
        assert np.array_equal(light, want), f"seed {seed}: frame {k}"


@pytest.mark.verilog
def test_loose_phased_at_ti_timing(test_name):
    """Single-block pulses under the loose RST_ACTIVE reading at TI's RST_ACTIVE and settle times
    (not scaled down): groups pulse while another's RST_ACTIVE is high, which lengthens the one
    pin's high. A group does not wait for that longer high (it is another group's reset): the
    commands equal the schedule model's, no pulse is late, every level exact."""
    p = schedule.plan(DMD, 200e6, reset_mode=ResetMode.SINGLE, strict_rst=False, depth=4).params
    first = next_ready(p, model_frames([(0, 4)], None), []) - PIN_TO_STROBE
    run, _model = check(p, [(0, 4)], None, [first], test_name)
    assert run.status["late"] == 0
