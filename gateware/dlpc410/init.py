"""DLPC410 start-up: wait for the controller, send the training pattern meanwhile.

After ARSTZ rises the DLPC410 configures itself (ECP2_FINISHED rises) and initialises the DMD
(INIT_ACTIVE high, about 220 ms, DLP7000 8.3). INIT_ACTIVE is read only once ECP2_FINISHED is
high (DLPC910). Until then the applications FPGA sends the training pattern (DLPC410 datasheet:
``0100`` repeating over four DDR edges, that is two DCLK cycles) on every data pin and DVALID,
and no command. ``running`` is high while ECP2_FINISHED is high and INIT_ACTIVE low; the
sequencer then keeps DVALID low for at least ``init_to_dvalid`` clocks (see
:mod:`spec.schedule`).

A controller that initialises again mid-run (INIT_ACTIVE high again, or ECP2_FINISHED low: it
was reset or reconfigured) has lost the DMD's memory and mirror state: ``running`` falls, the
fall is counted in ``restarts``, the training pattern goes out again, and the sequencer starts
over once the controller is ready (:class:`~gateware.dlpc410.control.FrameControl`).
"""

from amaranth import Module, Signal
from amaranth.lib import wiring
from amaranth.lib.cdc import FFSynchronizer
from amaranth.lib.wiring import In, Out

from spec.facts import TIMING

from ..counter import Counter
from .layouts import COUNTER_BITS

__all__ = ["Init", "TRAINING_EDGES"]

_pattern = int(TIMING["training_pattern"].value)
#: The training pattern's bit on each of its four DDR edges (rising, falling, rising, falling:
#: two DCLK cycles), the same on every data pin and on DVALID.
TRAINING_EDGES = tuple((_pattern >> (3 - k)) & 1 for k in range(4))


class Init(wiring.Component):
    """Start-up sequencing.

    Members
    -------
    ecp2_finished, init_active : In(1)
        From the DLPC410 (asynchronous; synchronised here).
    running : Out(1)
        The controller is ready for commands (ECP2_FINISHED high and INIT_ACTIVE low, two
        synchroniser cycles and one register late).
    restarts : Out(COUNTER_BITS)
        ``running`` fell: the controller initialises again (counted a cycle later).
    training : Out(1)
        High while the training pattern must be sent (not ``running``).
    rst_active : In(1), rst_active_synced : Out(1)
        RST_ACTIVE, synchronised.
    """
    ecp2_finished: In(1)
    init_active: In(1)
    rst_active: In(1)
    running: Out(1)
    restarts: Out(COUNTER_BITS)
    training: Out(1)
    rst_active_synced: Out(1)

    def elaborate(self, platform):
        m = Module()
        ecp2 = Signal()
        init = Signal(init=1)
        m.submodules.ecp2_sync = FFSynchronizer(self.ecp2_finished, ecp2)
        m.submodules.init_sync = FFSynchronizer(self.init_active, init, init=1)
        m.submodules.rst_sync = FFSynchronizer(self.rst_active, self.rst_active_synced)
        ready = ecp2 & ~init
        fell = Signal()
        m.d.sync += [self.running.eq(ready), fell.eq(self.running & ~ready)]
        m.submodules.restarts = restarts = Counter(COUNTER_BITS)
        m.d.comb += [restarts.inc.eq(fell), self.restarts.eq(restarts.count), self.training.eq(~self.running)]
        return m
