"""What the sync master must do, cycle by cycle: a plain model of its trigger rule, written
from its contract (:class:`gateware.sync.master.SyncMaster`), not from its code.

A trigger is obeyed (one pulse of ``width`` cycles on every board's line and the camera line)
when ``min_period`` cycles have passed since the last pulse and every board was ready as the
master sees the ready lines (through a synchroniser of ``stages`` cycles); otherwise it is
refused, counted as ``early`` (the period first) or ``not_ready``. The Amaranth simulation and
the generated Verilog are both checked against it.
"""

__all__ = ["SyncMasterModel", "scenario"]


class SyncMasterModel:
    def __init__(self, boards, *, min_period, stages=2):
        self.all = (1 << boards) - 1
        self.min_period, self.stages = min_period, stages
        self.history = [self.all] * (stages + 1)    # ready lines by cycle, as driven
        self.last = None
        self.counts = {"pulses": 0, "not_ready": 0, "early": 0}

    def cycle(self, t, ready, trigger):
        """Cycle ``t``'s inputs (``ready`` lines, a software ``trigger``); true when the
        trigger is obeyed."""
        self.history.append(ready)
        if not trigger:
            return False
        if self.last is not None and t - self.last < self.min_period:
            self.counts["early"] += 1
        elif self.history[-1 - self.stages] != self.all:
            self.counts["not_ready"] += 1
        else:
            self.counts["pulses"] += 1
            self.last = t
            return True
        return False


def scenario(rng, boards, cycles):
    """Random software triggers, and each board not ready now and then: ``(triggers, ready)``,
    the set of trigger cycles and a function of the cycle giving the ready lines."""
    triggers = set(rng.sample(range(50, cycles - 100), cycles // 50))
    windows = [(start, start + rng.randrange(30, 120), rng.randrange(boards))
               for start in sorted(rng.sample(range(0, cycles - 100), cycles // 250))]

    def ready(t):
        lines = (1 << boards) - 1
        for start, end, board in windows:
            if start <= t < end:
                lines &= ~(1 << board)
        return lines

    return triggers, ready
