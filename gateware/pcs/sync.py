"""Receive synchronisation (IEEE 802.3 clause 36.2.5.2.6, figure 36-9).

The link is in sync after three commas, each in an even position and followed by a valid data
code-group, with no invalid code-group between them. In sync, a bad code-group (invalid, or a
comma in an odd position) takes the machine one step down (SYNC_ACQUIRED_1 to 4), four good
ones in a row one step back up (the ``good_cgs`` count of the ``A`` states), and a bad one in
SYNC_ACQUIRED_4 loses sync. Every state entered, even the same one again, toggles ``rx_even``,
but the COMMA_DETECT states, which set it: the comma is even.
"""

from amaranth import Module, Mux, Signal
from amaranth.lib import enum, wiring
from amaranth.lib.wiring import In, Out

from .code_groups import CodeGroup

__all__ = ["Synchroniser", "SyncState"]


class SyncState(enum.Enum, shape=4):
    LOSS_OF_SYNC = 0
    COMMA_DETECT_1 = 1
    ACQUIRE_SYNC_1 = 2
    COMMA_DETECT_2 = 3
    ACQUIRE_SYNC_2 = 4
    COMMA_DETECT_3 = 5
    SYNC_ACQUIRED_1 = 6
    SYNC_ACQUIRED_2 = 7
    SYNC_ACQUIRED_2A = 8
    SYNC_ACQUIRED_3 = 9
    SYNC_ACQUIRED_3A = 10
    SYNC_ACQUIRED_4 = 11
    SYNC_ACQUIRED_4A = 12


_S = SyncState
#: In sync: the state a bad code-group leads to, and the one four good ones lead back to.
_DOWN = {_S.SYNC_ACQUIRED_1: _S.SYNC_ACQUIRED_2, _S.SYNC_ACQUIRED_2: _S.SYNC_ACQUIRED_3,
         _S.SYNC_ACQUIRED_2A: _S.SYNC_ACQUIRED_3, _S.SYNC_ACQUIRED_3: _S.SYNC_ACQUIRED_4,
         _S.SYNC_ACQUIRED_3A: _S.SYNC_ACQUIRED_4, _S.SYNC_ACQUIRED_4: _S.LOSS_OF_SYNC,
         _S.SYNC_ACQUIRED_4A: _S.LOSS_OF_SYNC}
_COUNTING = {_S.SYNC_ACQUIRED_2: _S.SYNC_ACQUIRED_2A, _S.SYNC_ACQUIRED_3: _S.SYNC_ACQUIRED_3A,
             _S.SYNC_ACQUIRED_4: _S.SYNC_ACQUIRED_4A}
_UP = {_S.SYNC_ACQUIRED_2A: _S.SYNC_ACQUIRED_1, _S.SYNC_ACQUIRED_3A: _S.SYNC_ACQUIRED_2,
       _S.SYNC_ACQUIRED_4A: _S.SYNC_ACQUIRED_3}
#: Comma detected: the state after the data code-group that must follow, and the state a comma
#: in an even position leads to from each ACQUIRE_SYNC state.
_AFTER_COMMA = {_S.COMMA_DETECT_1: _S.ACQUIRE_SYNC_1, _S.COMMA_DETECT_2: _S.ACQUIRE_SYNC_2,
                _S.COMMA_DETECT_3: _S.SYNC_ACQUIRED_1}
_NEXT_COMMA = {_S.ACQUIRE_SYNC_1: _S.COMMA_DETECT_2, _S.ACQUIRE_SYNC_2: _S.COMMA_DETECT_3}


class Synchroniser(wiring.Component):
    """Figure 36-9's state machine, a decoded code-group a cycle.

    Parameters
    ----------
    counter_width : int

    Members
    -------
    received : In(:class:`CodeGroup`)
        The decoder's code-group, one every cycle.
    signal_detect : In(1, init=1)
        The optical module's signal detect (low: loss of signal, so loss of sync).
    group : Out(:class:`CodeGroup`)
        ``received``, a cycle later, with ``even`` and ``sync_status`` of that code-group.
    even : Out(1)
        ``rx_even``: ``group`` is in an even position (a comma begins every ordered set there).
    sync_status : Out(1)
        In sync (a SYNC_ACQUIRED state); the receive process passes frames only then.
    state : Out(SyncState)
    losses : Out(counter_width)
        Times sync was lost (wraps).
    """

    def __init__(self, *, counter_width=16):
        super().__init__({
            "received": In(CodeGroup),
            "signal_detect": In(1, init=1),
            "group": Out(CodeGroup),
            "even": Out(1),
            "sync_status": Out(1),
            "state": Out(SyncState),
            "losses": Out(counter_width),
        })

    def elaborate(self, platform):
        m = Module()
        cg = self.received
        invalid = cg.invalid()
        comma = cg.comma & ~invalid
        data = ~cg.control & ~invalid
        # ``rx_even`` says the code-group before was even: a comma now is in an odd position.
        bad = invalid | (comma & self.even)
        good_cgs = Signal(2)

        nxt = Signal(SyncState)
        m.d.comb += nxt.eq(self.state)
        # Each state's ways out, the first whose condition holds taken; none: the same again.
        moves = {_S.LOSS_OF_SYNC: [(comma, _S.COMMA_DETECT_1)]}
        for detect, after in _AFTER_COMMA.items():
            moves[detect] = [(data, after), (~data, _S.LOSS_OF_SYNC)]
        for acquire, detect in _NEXT_COMMA.items():
            moves[acquire] = [(bad, _S.LOSS_OF_SYNC), (comma, detect)]
        for state, down in _DOWN.items():
            moves[state] = [(bad, down)]
            if state in _UP:
                moves[state].append((good_cgs == 3, _UP[state]))
            moves[state].append((1, _COUNTING.get(state, state)))
        with m.Switch(self.state):
            for state, ways in moves.items():
                with m.Case(state):
                    for index, (condition, target) in enumerate(ways):
                        with (m.Elif if index else m.If)(condition):
                            m.d.comb += nxt.eq(target)
        with m.If(~self.signal_detect):
            m.d.comb += nxt.eq(_S.LOSS_OF_SYNC)

        # The entry actions of the state entered.
        detecting = (nxt == _S.COMMA_DETECT_1) | (nxt == _S.COMMA_DETECT_2) | (nxt == _S.COMMA_DETECT_3)
        counting = (nxt == _S.SYNC_ACQUIRED_2A) | (nxt == _S.SYNC_ACQUIRED_3A) | (nxt == _S.SYNC_ACQUIRED_4A)
        synced = nxt.as_value() >= _S.SYNC_ACQUIRED_1.value
        m.d.sync += [
            self.state.eq(nxt),
            self.even.eq(detecting | ~self.even),
            good_cgs.eq(Mux(counting, good_cgs + 1, 0)),
            self.group.eq(cg),
            self.sync_status.eq(synced),
        ]
        with m.If(self.sync_status & ~synced):
            m.d.sync += self.losses.eq(self.losses + 1)
        return m
