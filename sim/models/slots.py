"""Reference model of the store's frame-slot policy (streaming mode), in plain Python.

It takes the same events as :class:`gateware.store.slots.FrameSlots` (rows as they reach the
store, asks, releases), each after the previous one has settled, and says what the gateware must
do: which rows are stored, which frame each ask gets, and every counter. Slots are tracked by
frame id, since the gateware may number them differently while a frame is being written.
"""

from gateware.store.slots import SlotCounters

__all__ = ["SlotPolicy"]


class SlotPolicy:
    def __init__(self, rows, slots, frame_bits=16):
        self.rows, self.slots, self.frame_bits = rows, slots, frame_bits
        self.frames = {}             # frame id -> {"state", "rows": set(), "depth"} for slots in use
        self.receiving = None        # frame id receiving
        self.last = None             # newest frame id started
        self.counters = {name: 0 for name, _ in SlotCounters.as_shape()}

    def _newer(self, frame):
        diff = (frame - self.last) % (1 << self.frame_bits)
        return 0 < diff < (1 << (self.frame_bits - 1))

    def _count(self, name):
        self.counters[name] += 1

    def in_state(self, state):
        return [f for f, s in self.frames.items() if s["state"] == state]

    def row(self, frame, row, depth):
        """One row of ``frame`` reaches the store; True when it is stored."""
        if row >= self.rows:
            self._count("rows_outside")
            return False
        if self.receiving is not None and frame == self.receiving:
            pass
        elif self.last is None or self._newer(frame):
            if self.receiving is not None:
                self._count("frames_abandoned")
                del self.frames[self.receiving]
            elif len(self.frames) == self.slots:
                self._count("rows_no_slot")
                return False
            self.frames[frame] = {"state": "RECEIVING", "rows": set(), "depth": depth}
            self.receiving = self.last = frame
        elif frame in self.in_state("SHOWN"):
            self._count("rows_shown")
            return False
        else:
            self._count("rows_stale")
            return False
        slot = self.frames[frame]
        if row in slot["rows"]:
            self._count("rows_duplicate")
            return False
        slot["rows"].add(row)
        if len(slot["rows"]) == self.rows:
            self._count("frames_complete")
            self.receiving = None
            for older in self.in_state("READY"):
                del self.frames[older]
                self._count("frames_replaced")
            slot["state"] = "READY"
        return True

    def can_answer(self):
        return bool(self.in_state("READY"))

    def ask(self):
        """The frame an ask gets (one must be ready)."""
        frame, = self.in_state("READY")
        self.frames[frame]["state"] = "SHOWN"
        return frame

    def release(self, frame):
        assert self.frames[frame]["state"] == "SHOWN"
        del self.frames[frame]
