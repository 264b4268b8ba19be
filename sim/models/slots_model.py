"""Reference model of the store's frame-slot policy (streaming mode), in plain Python.

It takes the same events as :class:`gateware.store.slots.FrameSlots` (rows as they reach the
store, asks, releases), each after the previous one has settled, and says what the gateware must
do: which rows are stored, which frame each ask gets, and every counter. Slots are tracked by
frame id, since the gateware may number them differently while a frame is being written.

Delta frames: a frame that carries only some rows names a whole frame held as its base and takes
its other rows and its bit depth from it; a base no frame shows or may show any more is KEPT
(it holds a slot) while a delta uses it.
"""

from gateware.store.slots import SlotCounters

__all__ = ["SlotPolicy"]


class SlotPolicy:
    def __init__(self, rows, slots, frame_bits=16):
        self.rows, self.slots, self.frame_bits = rows, slots, frame_bits
        self.frames = {}             # frame id -> {"state", "rows", "depth", "base", "needed"}, slots in use
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

    def row(self, frame, row, depth, base=None, carried=0):
        """One row of ``frame`` reaches the store; True when it is stored. ``carried`` nonzero: the
        frame is a delta of ``base`` carrying that many rows (it takes the others, and its depth,
        from ``base``, which must be a whole frame held)."""
        if row >= self.rows:
            self._count("rows_outside")
            return False
        if self.receiving is not None and frame == self.receiving:
            pass
        elif self.last is None or self._newer(frame):
            if carried > self.rows:
                self._count("rows_outside")
                return False
            if carried and not self._base_held(base):
                self._count("rows_no_base")
                return False
            if self.receiving is not None:
                self._count("frames_abandoned")
                self._drop(self.receiving)
            elif len(self.frames) == self.slots:
                self._count("rows_no_slot")
                return False
            self.frames[frame] = {"state": "RECEIVING", "rows": set(),
                                  "depth": self.frames[base]["depth"] if carried else depth,
                                  "base": base if carried else None,
                                  "needed": carried or self.rows}
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
        if len(slot["rows"]) == slot["needed"]:
            self._count("frames_complete")
            self.receiving = None
            slot["state"] = "READY"
            for older in self.in_state("READY"):
                if older != frame:
                    self._count("frames_replaced")
                    self._retire(older)
        return True

    def _base_held(self, base):
        """A delta may use ``base``: a whole frame, complete, still held."""
        held = self.frames.get(base)
        return held is not None and held["base"] is None and held["state"] in ("READY", "SHOWN", "KEPT")

    def _used(self, frame):
        return any(other["base"] == frame for other in self.frames.values())

    def _retire(self, frame):
        """``frame`` is no longer shown or showable: kept while a delta uses it, else freed."""
        if self._used(frame):
            self.frames[frame]["state"] = "KEPT"
        else:
            self._drop(frame)

    def _drop(self, frame):
        base = self.frames.pop(frame)["base"]
        if base is not None and self.frames[base]["state"] == "KEPT" and not self._used(base):
            del self.frames[base]

    def source(self, frame, row):
        """The frame whose words row ``row`` of ``frame`` shows."""
        held = self.frames[frame]
        return frame if held["base"] is None or row in held["rows"] else held["base"]

    def depth(self, frame):
        return self.frames[frame]["depth"]

    def can_answer(self):
        return bool(self.in_state("READY"))

    def ask(self):
        """The frame an ask gets (one must be ready)."""
        frame, = self.in_state("READY")
        self.frames[frame]["state"] = "SHOWN"
        return frame

    def release(self, frame):
        assert self.frames[frame]["state"] == "SHOWN"
        self._retire(frame)
