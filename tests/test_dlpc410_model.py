"""The DLPC410 + DMD model: legal sequences give the loaded data on the mirrors, and each rule
break injected on purpose raises that rule's named error."""

import numpy as np
import pytest

from sim.models.dlpc410_driver import Driver, Idle
from sim.models.dlpc410_model import RULES, Command, Dlpc410, RuleBreak, timing_cycles
from spec.facts import DMDS, TEST_DMD, BlockMode, RowMode

INIT = 20          # INIT_ACTIVE cycles after ARSTZ (the facts' 220 ms is 44 M cycles)
T = timing_cycles(200e6)
R, S = T["rst_active_cycles"], T["settle_cycles"]


def started(dmd=TEST_DMD, beats=1, **kw):
    """A model and a driver past initialisation, DVALID allowed from the driver's cycle on."""
    model = Dlpc410(dmd, beats=beats, init_cycles=INIT, **kw)
    driver = Driver(dmd, beats)
    driver.start(INIT)
    model.run(driver.items)
    driver.items.clear()
    return model, driver


def planes(dmd, seed, count=1):
    rng = np.random.default_rng(seed)
    return rng.integers(0, 2, (count, dmd.rows, dmd.columns), dtype=np.uint8)


def after_settle(driver, pulse_cycle):
    driver.wait_until(pulse_cycle + R + 1 + S)


def breaks(rule, model, items, match=None):
    with pytest.raises(RuleBreak, match=match) as info:
        model.run(items)
    assert info.value.rule is RULES[rule], str(info.value)
    assert str(info.value).startswith(f"{RULES[rule].source} {RULES[rule].title}: ")
    return info.value


# --- outputs ------------------------------------------------------------------------------------

def test_facts_in_cycles():
    assert (R, S) == (908, 1600)
    assert timing_cycles(400e6)["rst_active_cycles"] == 1816


def test_init_ecp2_and_rst_active_outputs():
    model = Dlpc410(TEST_DMD, init_cycles=10, ecp2_cycles=3, rst_active_cycles=5, settle_cycles=4)
    assert model.outputs()["init_active"] == 1 and model.outputs()["ecp2_finished"] == 0
    d = Driver(TEST_DMD)
    d.hold_reset(6)
    rise = d.cycle
    d.training(10)
    outs = [model.step(item) for item in d.items]      # outputs of cycles 1 .. 16
    assert [o["ecp2_finished"] for o in outs] == [0, 0] + [1] * 14
    # INIT_ACTIVE falls 10 cycles after ARSTZ rose (ECP2 finished before)
    assert [o["init_active"] for o in outs] == [1] * 15 + [0]
    assert model.init_end == rise + 10 and model.arstz_rise == rise
    assert model.outputs()["dmd_type"] == 0b1111
    d.items.clear()
    d.idle(64)
    p = d.pulse("global")
    model.run(d.items[:1])
    outs = [model.step(item) for item in d.items[1:]] + [model.idle(1) for _ in range(8)]
    # high from the cycle after the pulse, for 5 cycles
    assert [o["rst_active"] for o in outs] == [1] * 5 + [0] * 5
    assert model.log == [Command(p, "pulse", (0, 1, 2, 3), None, "global")]
    assert Dlpc410(DMDS["dlp7000"]).outputs()["dmd_type"] == 0b0001


# --- legal sequences ----------------------------------------------------------------------------

def test_load_and_global_pulse():
    model, d = started()
    plane, = planes(TEST_DMD, 1)
    first = d.cycle
    d.load(plane)
    p = d.pulse("global")
    d.idle(2)
    model.run(d.items)
    assert np.array_equal(model.memory, plane)
    assert np.array_equal(model.mirrors, plane)
    rows = [c for c in model.log if c.kind == "row"]
    assert [c.row for c in rows] == list(range(TEST_DMD.rows))
    assert [c.cycle for c in rows] == list(range(first, first + 2 * TEST_DMD.rows, 2))
    assert rows[0].mode == "FIRST" and {c.mode for c in rows[1:]} == {"NEXT"}
    assert all(model.pulse_cycles[b] == [p] for b in range(TEST_DMD.blocks))
    assert model.outputs()["rst_active"] == 1


@pytest.mark.parametrize("dmd", ["dlp7000", "dlp9500"])
def test_two_beats_per_cycle(dmd):
    """DCLK 400 MHz: a row cycle is half the cycles, each carrying two beats in edge order; the
    training pattern spans one cycle; the plane read back exactly, global pulse and clears
    (1080p: with their no-op rows) counted in cycles."""
    dmd = DMDS[dmd]
    model, d = started(dmd, beats=2)
    plane, = planes(dmd, 5)
    first = d.cycle
    d.load(plane)
    p = d.pulse("global")
    d.idle(2)
    model.run(d.items)
    assert np.array_equal(model.memory, plane) and np.array_equal(model.mirrors, plane)
    rows = [c for c in model.log if c.kind == "row"]
    per_row = dmd.dclk_per_row // 2
    assert [c.cycle for c in rows] == list(range(first, first + per_row * dmd.rows, per_row))
    assert p == first + per_row * dmd.rows
    d.items.clear()
    after_settle(d, p)
    c = d.clear(3)
    d.idle(2)
    model.run(d.items)
    assert not model.memory[3 * dmd.rows_per_block:4 * dmd.rows_per_block].any()
    assert model.log[-1] == Command(c, "clear", (3,))


def test_two_beats_rules_in_dclk_cycles():
    """At two beats a cycle the row-cycle rule counts DCLK cycles, and the training pattern
    repeats within a cycle."""
    model, d = started(DMDS["dlp7000"], beats=2)
    d.row(RowMode.ADDRESSED, rowad=3, cut=3)
    d.idle(2)
    breaks("row_cycle", model, d.items, "DVALID fell after 6 of 16 DCLK cycles")
    model = Dlpc410(DMDS["dlp7000"], beats=2, init_cycles=INIT)
    d = Driver(DMDS["dlp7000"], 2)
    d.hold_reset(4)
    d.training(6)
    d.items[-2]["din_a"] ^= 1 << 16            # pin 0 high on a falling edge where 0 is due
    breaks("init_training", model, d.items, "DIN_A\\(0\\) does not repeat 0100")


def test_row_modes_addressed_flip_and_complement():
    model, d = started()
    a, b = planes(TEST_DMD, 2, 2)
    order = list(np.random.default_rng(3).permutation(TEST_DMD.rows))
    d.load(a, rows=order)
    model.run(d.items)
    assert np.array_equal(model.memory, a)
    assert [c.row for c in model.log] == order
    d.items.clear()
    d.load(b, ns_flip=1)              # bottom up: 11 goes to the last row, 01 decrements
    model.run(d.items)
    assert np.array_equal(model.memory, b)
    assert [c.row for c in model.log[-TEST_DMD.rows:]] == list(range(TEST_DMD.rows - 1, -1, -1))
    d.items.clear()
    d.row(RowMode.ADDRESSED, rowad=5, bits=a[5], comp_data=1)
    d.row(RowMode.NOOP, bits=a[6])    # a no-op row writes nothing
    d.row(RowMode.NEXT, bits=a[6])    # the pointer follows ROWMD 10
    model.run(d.items)
    assert np.array_equal(model.memory[5], 1 - a[5])
    assert np.array_equal(model.memory[6], a[6])
    assert model.log[-1] == Command(model.log[-1].cycle, "row", (0,), 6, "NEXT")


def test_phased_block_pulses_and_clears():
    """Single, dual, quad and global pulses show each addressed block's memory, no other."""
    dmd = DMDS["dlp7000"]
    model, d = started(dmd)
    a, b = planes(dmd, 4, 2)
    rpb = dmd.rows_per_block
    d.load(a)
    p = d.pulse("global")
    after_settle(d, p)
    d.load(b)
    expect = a.copy()
    for kind, group, blocks in [("single", 5, [5]), ("dual", 3, [6, 7]), ("quad", 2, [8, 9, 10, 11]),
                                ("single", 15, [15])]:
        d.wait_until(d.cycle + R + 1)
        d.pulse(kind, group)
        for blk in blocks:
            expect[blk * rpb:(blk + 1) * rpb] = b[blk * rpb:(blk + 1) * rpb]
    d.wait_until(d.cycle + R + 1)
    model.run(d.items)
    assert np.array_equal(model.mirrors, expect)
    assert [c.mode for c in model.log if c.kind == "pulse"] == ["global", "single", "dual", "quad", "single"]
    d.items.clear()
    # clear block 0 (never pulsed since the global pulse, long settled) and block 9 (pulsed, settled)
    after_settle(d, model.pulse_cycles[15][-1])
    c0 = d.clear(0)
    c9 = d.clear(9)
    d.wait_until(d.cycle + 2)
    d.pulse("global")
    expect = b.copy()
    expect[:rpb] = 0
    expect[9 * rpb:10 * rpb] = 0
    model.run(d.items)
    assert np.array_equal(model.mirrors, expect)
    assert [(c.cycle, c.blocks) for c in model.log if c.kind == "clear"] == [(c0, (0,)), (c9, (9,))]


def test_other_blocks_load_while_one_settles():
    """DLPA008B 4.3: only the pulsed block is frozen; the others load meanwhile."""
    model, d = started()
    a, = planes(TEST_DMD, 5)
    d.pulse("single", 1)
    d.load(a, rows=[0, 1, 48, 95])
    model.run(d.items)
    assert np.array_equal(model.memory[[0, 1, 48, 95]], a[[0, 1, 48, 95]])


def test_dlp9500_two_words_per_beat_and_long_clear():
    dmd = DMDS["dlp9500"]
    model, d = started(dmd)
    a, = planes(dmd, 6)
    rows = [0, 71, 72, 1079]
    d.load(a, rows=rows)
    d.clear(1)                 # clear + 2 no-op rows; a pulse of another block may ride on them
    model.run(d.items)
    assert np.array_equal(model.memory[[0, 71]], a[[0, 71]])
    assert not model.memory[72:144].any()
    assert np.array_equal(model.memory[1079], a[1079])
    d.items.clear()
    d.row(blkmd=BlockMode.CLEAR, blkad=3)
    d.pulse("single", 0)
    d.row()
    model.run(d.items)
    assert [c.kind for c in model.log[-2:]] == ["clear", "pulse"]


def test_relaxed_rst_active_lets_other_groups_pulse():
    model, d = started(strict_rst_active=False)
    d.pulse("single", 0)
    d.pulse("dual", 1)
    d.pulse("single", 1)
    model.run(d.items)
    assert [c.blocks for c in model.log] == [(0,), (2, 3), (1,)]
    d.items.clear()
    d.pulse("quad", 0)
    breaks("rst_active", model, d.items, "pulse of block 0 6 cycles after its own pulse")


def test_back_to_back_rows_and_even_gaps():
    model, d = started()
    a, = planes(TEST_DMD, 7)
    d.row(RowMode.ADDRESSED, rowad=3, bits=a[3])
    d.row(RowMode.ADDRESSED, rowad=4, bits=a[4])
    d.idle(2)
    d.row(RowMode.ADDRESSED, rowad=5, bits=a[5])
    d.idle(1000)
    d.row(RowMode.ADDRESSED, rowad=6, bits=a[6])
    model.run(d.items)
    assert np.array_equal(model.memory[3:7], a[3:7])


def test_quiet_only_between_row_cycles():
    model, d = started()
    assert model.quiet()
    d.row(RowMode.ADDRESSED, rowad=1)
    model.step(d.items[0])
    assert not model.quiet()
    model.step(d.items[1])
    assert model.quiet()
    assert not Dlpc410(TEST_DMD).quiet()


def test_arstz_again_resets_memory_and_mirrors():
    model, d = started()
    a, = planes(TEST_DMD, 8)
    d.load(a)
    d.pulse("global")
    d.start(INIT)
    model.run(d.items)
    assert not model.memory.any() and not model.mirrors.any()
    assert model.outputs()["init_active"] == 0


# --- each rule broken on purpose ----------------------------------------------------------------

def test_rule_rst_active():
    model, d = started()
    p = d.pulse("single", 0)
    d.wait_until(p + R)               # RST_ACTIVE's last high cycle is p + R
    d.pulse("single", 3)
    breaks("rst_active", model, d.items, r"pulse of blocks \[3\] while RST_ACTIVE is high")


def test_rst_active_falls_in_time():
    model, d = started()
    p = d.pulse("single", 0)
    d.wait_until(p + R + 1)
    d.pulse("single", 3)
    model.run(d.items)
    assert model.pulse_cycles[3] == [p + R + 2]   # an even gap after the 2-cycle row


def test_rule_settle_row():
    model, d = started()
    p = d.pulse("single", 1)
    d.wait_until(p + R + 1 + 1203)
    d.row(RowMode.ADDRESSED, rowad=37)
    e = breaks("settle", model, d.items)
    assert str(e) == (f"DLPA008B 4.1 settle: row 37 of block 1 written 1203 cycles after RST_ACTIVE "
                      f"fell, needs 1600 (cycle {p + R + 1 + 1203})")


def test_settle_ends_in_time():
    model, d = started()
    p = d.pulse("single", 1)
    d.wait_until(p + R + 1 + S)
    d.row(RowMode.ADDRESSED, rowad=37)
    model.run(d.items)
    assert model.log[-1].row == 37


def test_paper_reading_loads_while_settling_and_spaces_flips():
    """The four-DMD paper's reading (never the default): a pulsed block loads as soon as
    RST_ACTIVE falls, but is not pulsed again sooner than the settle time after its pulse."""
    model, d = started(reading="paper")
    p = d.pulse("single", 1)
    d.wait_until(p + R + 1)
    d.row(RowMode.ADDRESSED, rowad=37)
    model.run(d.items)
    assert model.log[-1].row == 37
    d.items.clear()
    d.wait_until(p + S - 4)
    q = d.pulse("single", 1)      # on the row cycle before p + S
    assert q < p + S
    breaks("flip", model, d.items, f"pulse of block 1 {q - p} cycles after its last, needs {S}")
    model, d = started(reading="paper")
    p = d.pulse("single", 1)
    d.clear(1)
    breaks("settle", model, d.items, "while RST_ACTIVE is high")
    model, d = started(reading="paper")
    p = d.pulse("single", 1)
    d.wait_until(p + S)
    q = d.pulse("single", 1)
    model.run(d.items)
    assert model.pulse_cycles[1] == [p, q]


def test_rule_settle_clear_and_during_rst_active():
    model, d = started()
    d.pulse("global")
    d.clear(2)
    breaks("settle", model, d.items, "block of block 2 cleared 2 cycles after its pulse, while RST_ACTIVE")
    model, d = started()
    d.row(RowMode.ADDRESSED, rowad=50, blkmd=BlockMode.RESET, blkad=2)   # pulse and write at once
    breaks("settle", model, d.items, "row 50 of block 2 written 0 cycles after its pulse")


def test_rule_clear_overlap_same_row_cycle():
    model, d = started()
    d.row(RowMode.ADDRESSED, rowad=3, blkmd=BlockMode.CLEAR, blkad=2)
    breaks("clear_overlap", model, d.items, "clear of block 2 in a row cycle with ROWMD=10")


@pytest.mark.parametrize("what", ["row", "clear", "pulse"])
def test_rule_clear_overlap_1080p_noop_rows(what):
    model, d = started(DMDS["dlp9500"])
    d.row(blkmd=BlockMode.CLEAR, blkad=4)
    d.row()
    if what == "row":
        d.row(RowMode.ADDRESSED, rowad=0)
    elif what == "clear":
        d.row(blkmd=BlockMode.CLEAR, blkad=7)
    else:
        d.row(blkmd=BlockMode.MULTI, blkad=0b0010, rst2blkz=0)   # dual: blocks 4 and 5
    breaks("clear_overlap", model, d.items, "in row cycle 3 of 3 of the clear of block 4")


def test_rule_dvalid_gap():
    model, d = started()
    d.row()
    d.idle(3)
    d.row()
    breaks("dvalid_gap", model, d.items, "DVALID low for 3 cycles, must be even")


def test_rule_row_cycle_cut_short():
    dmd = DMDS["dlp7000"]
    model, d = started(dmd)
    start = d.row(RowMode.ADDRESSED, rowad=1, cut=9)
    d.idle(2)
    e = breaks("row_cycle", model, d.items,
               f"DVALID fell after 9 of 16 DCLK cycles of the row cycle from cycle {start}")
    assert e.cycle == start + 9


def test_rule_row_hold():
    model, d = started()
    d.row(RowMode.ADDRESSED, rowad=7)
    d.items[-1] = {**d.items[-1], "rowad": 8, "blkmd": 1}
    breaks("row_hold", model, d.items, "ROWAD, BLKMD changed in DCLK cycle 2 of the row cycle")


def test_rule_row_address():
    model, d = started()
    d.row(RowMode.ADDRESSED, rowad=TEST_DMD.rows)
    breaks("row_address", model, d.items, "ROWAD=96, the array has rows 0..95")


@pytest.mark.parametrize("case", ["past_end", "unset", "flip_below_first"])
def test_rule_row_pointer(case):
    model, d = started()
    if case == "past_end":
        d.load(np.zeros((TEST_DMD.rows, TEST_DMD.columns)))
        d.row(RowMode.NEXT)
        match = "from row 95 past the array"
    elif case == "unset":
        d.row(RowMode.NEXT)
        match = "before the pointer was set"
    else:
        d.row(RowMode.FIRST)
        d.row(RowMode.ADDRESSED, rowad=0)
        d.row(RowMode.NEXT, ns_flip=1)
        match = "from row 0 past the array"
    breaks("row_pointer", model, d.items, match)


@pytest.mark.parametrize("blkmd,blkad,rst2blkz,match", [
    (BlockMode.RESET, 4, 1, "BLKAD=4, the DMD has blocks 0..3"),
    (BlockMode.CLEAR, 9, 1, "BLKAD=9"),
    (BlockMode.MULTI, 0b0011, 1, "quad pulse with BLKAD=0011"),
    (BlockMode.MULTI, 0b0010, 0, "dual pulse of blocks 4.."),
    (BlockMode.MULTI, 0b1100, 1, "global is 10xx"),
])
def test_rule_block_address(blkmd, blkad, rst2blkz, match):
    model, d = started()
    d.row(blkmd=blkmd, blkad=blkad, rst2blkz=rst2blkz)
    breaks("block_address", model, d.items, match)


def test_rule_init_command():
    model = Dlpc410(TEST_DMD, init_cycles=INIT)
    d = Driver(TEST_DMD)
    d.hold_reset(4)
    d.training(5)
    d.items[-1] = {**d.items[-1], "dvalid": 1, "rowmd": 0b11}
    breaks("init_command", model, d.items, "ROWMD=11 BLKMD=00 while INIT_ACTIVE is high")


def test_rule_init_training():
    model = Dlpc410(TEST_DMD, init_cycles=INIT)
    d = Driver(TEST_DMD)
    d.hold_reset(4)
    d.training(6)
    d.items[-2] = {**d.items[-2], "din_b": d.items[-2]["din_b"] | 1 << 7}   # pin 7 rises once too often
    e = breaks("init_training", model, d.items, r"DIN_B\(7\) does not repeat 0100")
    assert e.cycle == d.cycle - 2
    model = Dlpc410(TEST_DMD, init_cycles=INIT)
    breaks("init_training", model, [Idle(4, {"arstz": 0}), Idle(4)], r"DIN_A\(0\)")


def test_no_training_check_when_disabled():
    model = Dlpc410(TEST_DMD, init_cycles=INIT, check_training=False)
    model.run([Idle(4, {"arstz": 0}), Idle(INIT + 64)])
    d = Driver(TEST_DMD)
    d.pulse()
    model.run(d.items)
    assert model.log[0].kind == "pulse"


def test_rule_init_dvalid():
    model = Dlpc410(TEST_DMD, init_cycles=INIT)
    d = Driver(TEST_DMD)
    d.start(INIT, after=62)
    d.row()
    breaks("init_dvalid", model, d.items, "DVALID high 62 clocks after INIT_ACTIVE fell, needs 64")


@pytest.mark.parametrize("grace", [0, 3])
def test_training_running_on_after_init(grace):
    """Training (DVALID toggling) that runs on for 3 cycles after INIT_ACTIVE fell is a break
    unless ``init_grace_cycles`` covers the FPGA's synchroniser latency."""
    model = Dlpc410(TEST_DMD, init_cycles=INIT, init_grace_cycles=grace)
    d = Driver(TEST_DMD)
    d.hold_reset(4)
    d.training(INIT + 3)
    d.items[-3:] = [{**item, "dvalid": i % 2} for i, item in enumerate(d.items[-3:], start=1)]
    d.idle(64)
    d.row()
    if grace:
        model.run(d.items)
        assert model.log == []
    else:
        breaks("init_dvalid", model, d.items, "DVALID high 0 clocks after INIT_ACTIVE fell")


def test_dlp650lnir_is_not_modelled():
    with pytest.raises(ValueError, match="not modelled"):
        Dlpc410(DMDS["dlp650lnir"])


def test_mirrors_settle_after_the_switching_time():
    model, d = started()
    a, b = planes(TEST_DMD, 9, 2)
    d.load(a)
    p = d.pulse("global")
    after_settle(d, p)
    d.load(b, rows=range(24, 48))
    q = d.pulse("single", 1)
    d.idle(2)
    model.run(d.items)
    switch = model.timing["switch_cycles"]
    assert switch == 2500
    assert not model.mirrors_at(p + switch - 1).any()
    assert np.array_equal(model.mirrors_at(p + switch), a)
    mixed = a.copy()
    mixed[24:48] = b[24:48]
    assert np.array_equal(model.mirrors_at(q + switch - 1), a)
    assert np.array_equal(model.mirrors_at(q + 10, motion_cycles=10), mixed)
    assert np.array_equal(model.mirrors, mixed)
