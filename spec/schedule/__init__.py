"""The schedule model: every DLPC410 command of a PWM frame, its cycle, the light per grey level.

Pure Python, shared by the host (what rate can this scene reach?) and the tests (the gateware's
command stream must equal this model's, cycle for cycle). It runs the very algorithm of
:class:`gateware.dlpc410.sequencer.Sequencer`, event by event instead of cycle by cycle.

The package reads bottom to top: :mod:`.terms` (the clock, the pipeline's latencies, the
parameters), :mod:`.model` (the algorithm, run event by event) and :mod:`.plan` (the plan finder
and the bound). Its names are all here.
"""

from .model import (  # noqa: F401
    _Model,
    back_to_back,
    frame_period,
    level_light,
    on_time,
    ready_cycle,
    shows_depth,
    simulate,
)
from .plan import (  # noqa: F401
    Plan,
    _distance_to_nearest,
    bound,
    paper_eq_rate_hz,
    plan,
    timeline,
)
from .terms import (  # noqa: F401
    DECISION_TO_PINS,
    END_TO_TRIGGER,
    FABRIC_HZ,
    FALL_LATENCY,
    INIT_TO_DVALID,
    MIN_SETTLE,
    OFFER_LAG,
    PACE_LAG,
    PAPER_SETTLE_CYCLES,
    RELOAD_LEAD,
    RST_MARGIN,
    WORD_FIFO_ROWS,
    Frame,
    Params,
    Result,
    beats_at,
    even,
    exponents,
    flush_rows,
    groups,
    pulse_encoding,
    reload_bound,
    reload_cycles,
    row_cycles,
    row_rate_words,
    trigger_lead,
)

__all__ = [
    "Params", "Frame", "Result", "Plan", "exponents", "groups", "pulse_encoding", "simulate",
    "FABRIC_HZ", "back_to_back", "beats_at", "row_cycles", "row_rate_words", "plan", "bound",
    "paper_eq_rate_hz", "level_light", "INIT_TO_DVALID", "RELOAD_LEAD", "WORD_FIFO_ROWS",
    "flush_rows", "PAPER_SETTLE_CYCLES", "MIN_SETTLE", "RST_MARGIN", "FALL_LATENCY",
    "DECISION_TO_PINS", "PACE_LAG", "even", "trigger_lead", "shows_depth", "ready_cycle",
    "reload_bound", "reload_cycles", "on_time", "frame_period", "timeline",
]
