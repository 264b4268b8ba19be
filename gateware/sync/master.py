"""The sync master: one sync pulse per frame to every projector board of a tiled display.

A tiled display is several projector boards, each on its own crystal, showing one scene. The
master takes the frame trigger (the TTL pin, a free-running period or a host command, as a
board's own :class:`~gateware.dlpc410.trigger.Trigger`), and sends one pulse on every board's
sync line at once, from flip-flops the platform places in the output pads (so that the pulses
leave within the pads' skew of each other), plus a camera trigger. Each board answers on a ready
line: high while it has a frame loaded and waits at its anchor plane for the pulse. A trigger is
obeyed only when every board is ready and the frame period the boards can keep has passed since
the last pulse; otherwise it is refused and counted (a board not ready, or too early).
"""

from amaranth import Cat, Module, Signal
from amaranth.lib import wiring
from amaranth.lib.cdc import FFSynchronizer
from amaranth.lib.wiring import In, Out

from ..countdown import Countdown
from ..dlpc410.trigger import Trigger
from ..registers import DURATION_BITS, TriggerMode

__all__ = ["SyncMaster"]


class SyncMaster(wiring.Component):
    """Sync pulses for ``boards`` projector boards (one clock domain, ``sync``).

    Parameters
    ----------
    boards : int

    Members
    -------
    mode : In(TriggerMode)
        What starts a frame: the trigger pin, a period, or ``soft`` (``SYNC`` is not used).
    period : In(DURATION_BITS)
        Trigger period in :attr:`~gateware.registers.TriggerMode.PERIODIC`.
    min_period : In(DURATION_BITS)
        The shortest frame period the boards keep: a trigger sooner after the last pulse is
        refused.
    width : In(16)
        Cycles each sync and camera pulse lasts (at least 1).
    run : In(1)
        Triggers are obeyed while high.
    trigger_in : In(1)
        The frame trigger pin (asynchronous).
    soft : In(1)
        A host's trigger: a one-cycle pulse.
    ready : In(boards)
        The boards' ready lines (asynchronous).
    ready_seen : Out(boards)
        The ready lines as the master obeys them (synchronised).
    sync_out : Out(boards)
        The sync pulses, all the same cycles.
    camera_out : Out(1)
        The camera trigger, with the sync pulses.
    pulses, not_ready, early : Out(32)
        Pulses sent; triggers refused because a board was not ready; because the frame period
        had not passed.
    """

    def __init__(self, boards):
        self._boards = boards
        super().__init__({
            "mode": In(TriggerMode),
            "period": In(DURATION_BITS),
            "min_period": In(DURATION_BITS),
            "width": In(16),
            "run": In(1),
            "trigger_in": In(1),
            "soft": In(1),
            "ready": In(boards),
            "ready_seen": Out(boards),
            "sync_out": Out(boards),
            "camera_out": Out(1),
            "pulses": Out(32),
            "not_ready": Out(32),
            "early": Out(32),
        })

    def elaborate(self, platform):
        m = Module()
        m.submodules.trigger = trigger = Trigger()
        m.d.comb += [trigger.mode.eq(self.mode), trigger.period.eq(self.period), trigger.run.eq(self.run),
                     trigger.pin.eq(self.trigger_in), trigger.soft.eq(self.soft)]
        ready = self.ready_seen
        m.submodules.ready_sync = FFSynchronizer(self.ready, ready)
        m.submodules.spacing = spacing = Countdown(DURATION_BITS)   # since the last pulse
        m.submodules.hold = hold = Countdown(16)                     # the pulse being sent

        go = Signal()
        with m.If(trigger.strobe & self.run):
            with m.If(~spacing.done):
                m.d.sync += self.early.eq(self.early + 1)
            with m.Elif(~ready.all()):
                m.d.sync += self.not_ready.eq(self.not_ready + 1)
            with m.Else():
                m.d.comb += go.eq(1)
                m.d.sync += self.pulses.eq(self.pulses + 1)
        m.d.comb += [spacing.load.eq(go), spacing.value.eq(self.min_period),
                     hold.load.eq(go), hold.value.eq(self.width)]
        high = Signal()
        m.d.sync += high.eq(go | (high & ~hold.done))
        # one register per output: the platform puts each in its pad
        m.d.sync += [self.sync_out.eq(Cat(high for _ in range(self._boards))), self.camera_out.eq(high)]
        return m
