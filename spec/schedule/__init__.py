"""The schedule model: every DLPC410 command of a PWM frame, its cycle, the light per grey level.

Pure Python, shared by the host (what rate can this scene reach?) and the tests (the gateware's
command stream must equal this model's, cycle for cycle). It runs the very algorithm of
:class:`gateware.dlpc410.sequencer.Sequencer`, event by event instead of cycle by cycle.

The package reads bottom to top: :mod:`.terms` (the clock, the pipeline's latencies, the
parameters), :mod:`.model` (the algorithm, run event by event), :mod:`.measures` (what a run of it
says of a plan) and :mod:`.planner` (the plan finder and the bound). Its names are all here.
"""

from . import measures, model, planner, terms
from .measures import (  # noqa: F401
    back_to_back,
    frame_period,
    level_light,
    on_time,
    ready_cycle,
)
from .model import (  # noqa: F401
    _Model,
    shows_depth,
    simulate,
)
from .planner import (  # noqa: F401
    Plan,
    bound,
    paper_eq_rate_hz,
    plan,
    plan_gated,
    timeline,
)
from .terms import (  # noqa: F401
    DECISION_TO_PINS,
    END_TO_TRIGGER,
    FABRIC_HZ,
    FALL_LATENCY,
    INIT_TO_DVALID,
    LIGHT_FALL,
    LIGHT_RISE,
    MIN_SETTLE,
    MIRRORS_SETTLED,
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

__all__ = [*terms.__all__, *model.__all__, *measures.__all__, *planner.__all__]
