"""The plan finder (:mod:`spec.plan_search`): it tries every reset mode, plane order and hide
threshold, and its choice is the fastest legal plan; that plan plays on the gateware at the
period the model gives it, every level exact; the host CLI uses it before sending."""

import pytest

from host import cli
from sim.bench.rig_rate import measured_rate
from spec import plan_search, schedule
from spec.facts import TEST_DMD
from spec.registers import PlaneOrder, ResetMode

#: RST_ACTIVE and settle scaled down so that the search and the frames run quickly.
FAST = {"t_rst_s": 20 / 200e6, "t_settle_s": 30 / 200e6}


def test_the_finder_picks_the_fastest_legal_plan():
    found = plan_search.find(TEST_DMD, 200e6, workers=1, **FAST)
    legal = [c for c in found.candidates if c.plan is not None]
    assert found.plan.frame_cycles == min(c.plan.frame_cycles for c in legal)
    # every reset mode and order was planned as schedule.plan plans it alone
    for mode in ResetMode:
        for order in plan_search.ORDERS:
            alone = schedule.plan(TEST_DMD, 200e6, reset_mode=mode, **plan_search.order_kwargs(order, 8), **FAST)
            mine = [c for c in found.candidates if c.reset_mode == mode and c.order == order]
            assert mine[0].plan.params == alone.params and mine[0].plan.frame_cycles == alone.frame_cycles
            # and higher hide thresholds after it, legal or not
            assert len(mine) >= 2 and all(c.hide > alone.params.hide for c in mine[1:]), (mode, order)
    # the legal ones play on time
    assert all(schedule.on_time(TEST_DMD, c.plan.params, schedule.Frame(0, 8)) for c in legal)
    assert found.binds.startswith(f"{found.best.reset_mode.name}, {found.best.order_name}")
    assert "* " in found.table()


def test_interleaved_order_puts_each_short_plane_behind_a_long_one():
    assert plan_search.interleaved(8) == (7, 1, 6, 2, 5, 3, 4, 0)
    for depth in range(1, 9):
        table = plan_search.interleaved(depth)
        assert sorted(table) == list(range(depth)) and table[-1] == 0
        kw = plan_search.order_kwargs(PlaneOrder.TABLE, depth)
        assert sorted(kw["order_table"]) == list(range(8))
        assert schedule.exponents(kw["order"], kw["order_table"], depth) == list(table)


@pytest.mark.verilog
def test_the_finders_plan_plays_at_its_period_on_the_gateware(test_name):
    """The finder's plan played back to back on the sequencer's generated Verilog: the period
    measured on the pins is the plan's, the commands the schedule model's, a frame between two
    others exact in every level (global) or the rule model silent (phased)."""
    found = plan_search.find(TEST_DMD, 200e6, workers=1, trigger_hold=True, **FAST)
    period, _, error = measured_rate("test", found.best.reset_mode.name, True, 200e6, plan=found.plan, name=test_name)
    assert period == found.plan.frame_cycles
    assert error == 0.0              # every level of the frame between two others exact


def test_cli_configure_best_prints_the_search_and_sends_the_fastest(capsys):
    assert cli.main(["configure", "--dmd", "test", "--dclk", "200e6", "--best", "--dry-run"]) == 0
    out = capsys.readouterr().out
    found = plan_search.find(TEST_DMD, 200e6)
    assert f"fastest: {found.binds}" in out and found.table() in out
    assert f"{found.plan.rate_hz:.1f} frames/s" in out
