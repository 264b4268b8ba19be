"""The sequencer's register set, from the protocol (``sync``) to the sequencer (``dmd``).

A sequencer record's register set must reach the sequencer whole, and only when the sequencer
may take it: while it rests (:attr:`gateware.dlpc410.sequencer.Sequencer.at_rest`: before the
first frame, or every group loaded and waiting for a trigger). Frames may play for a long time
(a chained run rests only when disarmed), so sets wait in a mailbox in ``sync`` where the newest replaces an
older one not yet sent; from there they cross through a small :class:`amaranth.lib.fifo.AsyncFIFO`
(every bit of a set crosses together) into a register on the sequencer side, which applies it
when the sequencer rests, telling the sequencer to load its first plane again under the new
registers. Disarmed, the sequencer sees the trigger mode as software and frames not chained (the
set itself is kept, and applies again once armed).
"""

from amaranth import DomainRenamer, Module, Mux, Signal
from amaranth.lib import fifo, stream, wiring
from amaranth.lib.wiring import In, Out

from gateware.registers import Registers, TriggerMode

from ..counter import Counter

__all__ = ["RegisterCrossing"]


def _disarmed(regs):
    """The registers ``regs`` (a constant) as the sequencer sees them disarmed."""
    layout, bits = Registers.as_shape(), regs.as_bits()
    for name, value in (("chain", 0), ("trigger", TriggerMode.SOFTWARE.value)):
        field = layout[name]
        bits = bits & ~(((1 << field.width) - 1) << field.offset) | value << field.offset
    return layout.from_bits(bits)


class RegisterCrossing(wiring.Component):
    """Register sets from ``sync`` into ``dmd``, applied only while the sequencer rests.

    Parameters
    ----------
    power_up : dict or :class:`amaranth.lib.data.Const` of :class:`Registers`
        The registers from reset until the first set is applied.
    depth : int
        Sets in flight between the domains.
    armed : bool
        Whether the projector is armed from reset.

    Members
    -------
    sets : In(stream.Signature(Registers))
        Register sets of valid sequencer records (``sync``); always ready.
    superseded : Out(32)
        Sets replaced in the mailbox by a newer one before they left it (``sync``).
    at_rest : In(1)
        The sequencer may take new registers (``dmd``).
    armed : In(1)
        The projector is armed (``dmd``, synchronised).
    regs : Out(Registers)
        The registers the sequencer runs with (``dmd``); they change only while ``at_rest``, but
        for the trigger mode (software while disarmed) and ``chain`` (low while disarmed), which
        follow ``armed`` a cycle later. Registered, so that no gate lies between them and the
        sequencer's decisions.
    reload : Out(1)
        High in the cycle a set is applied (``dmd``), for the sequencer's ``reload``.
    applied : Out(32)
        Sets applied (``dmd``).
    """

    def __init__(self, power_up, *, depth=2, armed=True):
        self._depth = depth
        self._power_up = power_up = Registers.const(power_up)
        if not armed:
            power_up = _disarmed(power_up)
        super().__init__({
            "sets": In(stream.Signature(Registers)),
            "superseded": Out(32),
            "at_rest": In(1),
            "armed": In(1, init=armed),
            "regs": Out(Registers, init=power_up),
            "reload": Out(1),
            "applied": Out(32),
        })

    def elaborate(self, platform):
        m = Module()
        m.submodules.fifo = crossing = fifo.AsyncFIFO(width=Registers.as_shape().size, depth=self._depth,
                                                      w_domain="sync", r_domain="dmd")
        into, out = crossing.w_stream, crossing.r_stream
        # ---- sync: the mailbox, newest first ----
        pending = Signal(Registers)
        full = Signal()
        m.d.comb += [into.payload.eq(pending), into.valid.eq(full), self.sets.ready.eq(1)]
        with m.If(self.sets.valid):
            m.d.sync += [pending.eq(self.sets.payload), full.eq(1)]
            with m.If(full & ~into.ready):
                m.d.sync += self.superseded.eq(self.superseded + 1)
        with m.Elif(into.ready):
            m.d.sync += full.eq(0)

        # ---- dmd: taken into a register as it arrives, applied whole while the sequencer rests
        # (the FIFO's read side does not wait on the sequencer's decisions) ----
        held, holding = Signal(Registers), Signal()
        m.d.comb += out.ready.eq(~holding)
        with m.If(out.valid & ~holding):
            m.d.dmd += [held.eq(out.payload), holding.eq(1)]
        m.submodules.applied = applied = DomainRenamer({"sync": "dmd"})(Counter(len(self.applied)))
        m.d.comb += [self.applied.eq(applied.count), applied.inc.eq(holding & self.at_rest)]
        # the set applied, as sent, of the two registers arming gates
        chain = Signal(init=self._power_up.chain)
        trigger = Signal(TriggerMode, init=self._power_up.trigger)
        applying = holding & self.at_rest
        with m.If(applying):
            m.d.comb += self.reload.eq(1)
            m.d.dmd += [self.regs.eq(held), holding.eq(0), chain.eq(held.chain), trigger.eq(held.trigger)]
        m.d.dmd += [self.regs.chain.eq(Mux(applying, held.chain, chain) & self.armed),
                    self.regs.trigger.eq(Mux(self.armed, Mux(applying, held.trigger, trigger), TriggerMode.SOFTWARE))]
        return m
