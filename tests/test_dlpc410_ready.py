"""The sequencer's ready line (the line a tiled display's sync master reads, ``Sequencer.ready``) on
its generated Verilog (:mod:`sim.rigs.seq_rig`, testbench :mod:`sim.tb.seq_rig_tb`, TEST_DMD): high
exactly while a trigger would be obeyed at once. It rises when every group holds the frame's first
plane, the cycle the schedule model's groups are all loaded; it is low while a frame plays and while
a trigger is held; a trigger that finds it high starts the frame within the usual latency, and one
that finds it low is held (``trigger_hold``) and obeyed on the cycle the groups are ready again,
with the line staying low."""

import pytest

from gateware.dlpc410.trigger import PIN_TO_STROBE
from sim.rigs.seq_rig import run_rig
from spec import schedule
from spec.facts import TEST_DMD

DMD = TEST_DMD
FAST = {"t_rst_s": 20 / 200e6, "t_settle_s": 30 / 200e6}


def _high_spans(changes, end):
    """``[(rise, fall)]`` of a line from its ``(now, level)`` changes (an open span ends at ``end``)."""
    spans, rise = [], None
    for now, level in changes:
        if level and rise is None:
            rise = now
        elif not level and rise is not None:
            spans.append((rise, now))
            rise = None
    return spans + ([(rise, end)] if rise is not None else [])


@pytest.mark.verilog
def test_ready_line_tells_when_a_trigger_is_obeyed_at_once(test_name):
    p = schedule.plan(DMD, 200e6, depth=8, trigger_hold=True, **FAST).params
    frame = schedule.Frame(0, 8)
    ready = schedule.ready_cycle(DMD, p, frame)
    first = ready + 20 - PIN_TO_STROBE                  # finds the line high
    second = first + 200                                # while the first frame plays: held
    # (one frame, shown twice: a second one offered while waiting would be loaded again)
    model = schedule.simulate(DMD, p, [frame], [first + PIN_TO_STROBE, second + PIN_TO_STROBE])
    assert len(model.frame_starts) == 2
    end = model.frame_starts[1] + 2 * (model.frame_starts[1] - model.frame_starts[0])
    run = run_rig(DMD, p, [(0, 8)], pins=[first, second], cycles=end, name=test_name)
    assert run.status["triggers"] == 2 and run.status["held"] == 1 and run.status["overruns"] == 0
    spans = _high_spans(run.ready, end)
    # the line is registered: it says, a cycle late, what a trigger would have found
    # the first rise follows the cycle the model's groups are all loaded (the same time base)
    assert spans and spans[0][0] == ready + 1, (spans[:2], ready)
    # the first trigger's strobe takes it down; the held one keeps it down until its frame starts
    assert spans[0][1] == first + PIN_TO_STROBE + 2, (spans[0], first + PIN_TO_STROBE)
    assert len(spans) == 2, spans
    # high again once the second frame has played and every group holds the first plane again,
    # the cycle after the model's groups are all loaded after their last pulse; and it stays high
    again = max(g.loaded_at for g in model.groups)
    assert spans[1] == (again + 1, end), (spans[1], again)
    # never high while a frame is shown
    shown = _high_spans(run.sync_out, end)
    assert len(shown) == 2
    assert not any(r < f_end and s < r_end for r, r_end in spans for s, f_end in shown), (spans, shown)
