"""Every counter the status reply carries is as wide as its field: none wraps inside it (a 16-bit
``frames_shown`` wrapped after about four minutes at 266 Hz, and ``store_rows_refused``, a sum of
five counters, fell by 65,536 whenever one of them wrapped)."""

from amaranth import Shape
from amaranth.lib import data

from gateware.dlpc410.layouts import Status
from gateware.dlpc410.register_crossing import RegisterCrossing
from gateware.registers import Registers
from gateware.store.slots import SlotCounters
from gateware.sync.clock_trim import ClockTrim
from spec import records

WIDTHS = dict(records.SYSTEM_STATUS)

#: The sequencer's status counters and the status reply fields they fill.
SEQUENCER = {"frames": "frames_shown", "triggers": "triggers", "overruns": "trigger_overruns",
             "early": "triggers_early", "held": "triggers_held", "late": "pulses_late",
             "underruns": "row_underruns", "bad_frames": "frames_bad_depth",
             "rst_late": "rst_active_late", "rst_faults": "rst_active_faults",
             "restarts": "dlpc410_restarts", "rst_longest": "rst_active_cycles_max",
             "period_short": "frames_period_short", "after_end": "triggers_after_end"}
#: The store's counters: five reported alone, the row refusals as one sum.
STORE = {"frames_complete": "store_frames_complete", "frames_replaced": "store_frames_replaced",
         "frames_abandoned": "store_frames_abandoned", "calibration_losses": "store_calibration_losses",
         "frames_lost": "store_frames_lost",
         **{name: "store_rows_refused" for name in ("rows_outside", "rows_stale", "rows_shown",
                                                    "rows_duplicate", "rows_no_slot")}}


def width(layout, name):
    return Shape.cast(data.Layout.cast(layout)[name].shape).width


def test_sequencer_counters_fill_their_fields():
    assert set(SEQUENCER) == {name for name, _ in data.Layout.cast(Status)} - {"now"}
    for name, field in SEQUENCER.items():
        assert width(Status, name) == WIDTHS[field], name


def test_store_counters_fill_their_fields():
    for name, field in STORE.items():
        assert width(SlotCounters, name) == WIDTHS[field], name


def test_register_sets_counted_in_full():
    crossing = RegisterCrossing(Registers.const({}))
    crossing._MustUse__silence = True     # only its signature is wanted, not its logic
    members = crossing.signature.members
    for name in ("applied", "superseded"):
        assert members[name].shape == WIDTHS[f"registers_{name}"], name


def test_clock_loop_slips_counted_in_full():
    # the class's annotations: an instance never elaborated would be reported unused
    assert Shape.cast(ClockTrim.__annotations__["slips"].shape).width == WIDTHS["clock_loop_slips"]
