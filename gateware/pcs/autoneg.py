"""1000BASE-X auto-negotiation (IEEE 802.3 clause 37, figure 37-6), base page only.

Each side sends its base page (clause 37.2.1) in /C/ ordered sets until it has received three
matching config words from the other (``ability_match``, the ACK bit ignored), then sends it with
ACK set until it has received three matching words with ACK set (``acknowledge_match``) that
agree with the ones matched first (``consistency_match``). It goes on sending for a link timer,
then sends idles until it has received three idles (``idle_match``) and a link timer more has
passed: LINK_OK, and the MAC's frames may pass. Three consecutive words are three received one
after the other with no idle between them, from /C1/ or /C2/ alike.

Back to AN_ENABLE (and to AN_RESTART, sending all-zero words for a link timer): on
``mr_restart_an``, on loss of sync, on RUDI(INVALID) while not sending data (an invalid
code-group between ordered sets, clause 36's RX_INVALID), on matching all-zero words (the
partner restarting) in any state after ABILITY_DETECT, and on any matching words in LINK_OK.
Left out: next pages (``mr_np_able`` is false), priority resolution (the MAC reads the partner's
page), remote fault, and ``an_sync_status``'s own hysteresis (sync_status is used as it is).
"""

from amaranth import Module, Mux, Signal
from amaranth.lib import enum, stream, wiring
from amaranth.lib.wiring import In, Out

__all__ = ["AutoNegotiation", "AnState", "Xmit", "FULL_DUPLEX", "PAUSE", "ACK"]

#: Base page bits (clause 37.2.1.1-5): full duplex, the two pause bits, acknowledge.
FULL_DUPLEX, PAUSE, ACK = 1 << 5, 7, 1 << 14


class Xmit(enum.Enum, shape=2):
    """What the transmit process sends between frames (clause 36.2.5.1.3)."""
    IDLE = 0
    CONFIGURATION = 1
    DATA = 2


class AnState(enum.Enum, shape=3):
    AN_ENABLE = 0
    AN_RESTART = 1
    AN_DISABLE_LINK_OK = 2
    ABILITY_DETECT = 3
    ACKNOWLEDGE_DETECT = 4
    COMPLETE_ACKNOWLEDGE = 5
    IDLE_DETECT = 6
    LINK_OK = 7


_S = AnState


class AutoNegotiation(wiring.Component):
    """Figure 37-6's state machine over the receive process's indications.

    Parameters
    ----------
    link_timer : int
        Cycles of the link timer (10 ms nominal, 1 250 000 at 125 MHz; short in tests).
    counter_width : int

    Members
    -------
    configs : In(stream.Signature(16, always_ready=True))
        Each config word received (RUDI(/C/) with ``rx_Config_Reg``).
    idle : In(1)
        An /I/ received (RUDI(/I/)).
    invalid : In(1)
        An invalid code-group received between ordered sets (RUDI(INVALID)).
    sync_status : In(1)
    mr_an_enable : In(1, init=1)
        Low: no negotiation, data at once (AN_DISABLE_LINK_OK).
    mr_restart_an : In(1)
        High for a cycle (or longer): negotiate again.
    pause : In(2)
        PS1 and PS2 to advertise (clause 37.2.1.4).
    mr_adv_ability : Out(16)
        Our base page: full duplex, ``pause``.
    mr_lp_adv_ability : Out(16)
        The partner's base page as acknowledged (its ACK bit set), from COMPLETE_ACKNOWLEDGE on.
    mr_an_complete : Out(1)
        In LINK_OK.
    xmit : Out(Xmit)
        For the transmit process, and for the gate that lets frames through only in DATA.
    tx_config : Out(16)
        ``tx_Config_Reg``: the word to send while ``xmit`` is CONFIGURATION.
    state : Out(AnState)
    restarts : Out(counter_width)
        Times the machine went back to AN_ENABLE (wraps).
    """

    def __init__(self, *, link_timer=1_250_000, counter_width=16):
        self._link_timer = link_timer
        super().__init__({
            "configs": In(stream.Signature(16, always_ready=True)),
            "idle": In(1),
            "invalid": In(1),
            "sync_status": In(1),
            "mr_an_enable": In(1, init=1),
            "mr_restart_an": In(1),
            "pause": In(2),
            "mr_adv_ability": Out(16),
            "mr_lp_adv_ability": Out(16),
            "mr_an_complete": Out(1),
            "xmit": Out(Xmit),
            "tx_config": Out(16),
            "state": Out(AnState),
            "restarts": Out(counter_width),
        })

    def elaborate(self, platform):
        m = Module()
        m.d.comb += self.mr_adv_ability.eq(FULL_DUPLEX | self.pause << PAUSE)

        # The match functions (clause 37.3.1.4): runs of words since the last idle.
        rx_config = Signal(16)  # rx_Config_Reg, the last word received
        same = Signal(range(4))  # words in a row equal to it, ACK ignored
        acked = Signal(range(4))  # words in a row equal to it, with ACK set
        idles = Signal(range(4))  # idles in a row
        matched = Signal(16)  # the word ability_match held for into ACKNOWLEDGE_DETECT
        word = self.configs.payload
        with m.If(self.configs.valid):
            alike = (same != 0) & ((word & ~ACK) == (rx_config & ~ACK))
            m.d.sync += [rx_config.eq(word), idles.eq(0), same.eq(Mux(alike, same + (same != 3), 1))]
            with m.If(~word[14]):
                m.d.sync += acked.eq(0)
            with m.Elif((acked != 0) & (word == rx_config)):
                m.d.sync += acked.eq(acked + (acked != 3))
            with m.Else():
                m.d.sync += acked.eq(1)
        with m.Elif(self.idle):
            m.d.sync += [same.eq(0), acked.eq(0), idles.eq(idles + (idles != 3))]
        ability_match = same == 3
        acknowledge_match = acked == 3
        consistency_match = (matched & ~ACK) == (rx_config & ~ACK)
        idle_match = idles == 3
        zero = rx_config == 0
        restarting = ability_match & zero

        timer = Signal(range(self._link_timer + 1))
        link_timer_done = timer == self._link_timer

        state = self.state
        nxt = Signal(AnState)
        m.d.comb += nxt.eq(state)
        with m.Switch(state):
            with m.Case(_S.AN_ENABLE):
                m.d.comb += nxt.eq(_S.AN_RESTART)
                with m.If(~self.mr_an_enable):
                    m.d.comb += nxt.eq(_S.AN_DISABLE_LINK_OK)
            with m.Case(_S.AN_RESTART):
                with m.If(link_timer_done):
                    m.d.comb += nxt.eq(_S.ABILITY_DETECT)
            with m.Case(_S.AN_DISABLE_LINK_OK):
                with m.If(self.mr_an_enable):
                    m.d.comb += nxt.eq(_S.AN_ENABLE)
            with m.Case(_S.ABILITY_DETECT):
                with m.If(ability_match & ~zero):
                    m.d.comb += nxt.eq(_S.ACKNOWLEDGE_DETECT)
                    m.d.sync += matched.eq(rx_config)
            with m.Case(_S.ACKNOWLEDGE_DETECT):
                with m.If((acknowledge_match & ~consistency_match) | restarting):
                    m.d.comb += nxt.eq(_S.AN_ENABLE)
                with m.Elif(acknowledge_match):
                    m.d.comb += nxt.eq(_S.COMPLETE_ACKNOWLEDGE)
            with m.Case(_S.COMPLETE_ACKNOWLEDGE):
                with m.If(restarting):
                    m.d.comb += nxt.eq(_S.AN_ENABLE)
                with m.Elif(link_timer_done):
                    m.d.comb += nxt.eq(_S.IDLE_DETECT)
            with m.Case(_S.IDLE_DETECT):
                with m.If(restarting):
                    m.d.comb += nxt.eq(_S.AN_ENABLE)
                with m.Elif(idle_match & link_timer_done):
                    m.d.comb += nxt.eq(_S.LINK_OK)
            with m.Case(_S.LINK_OK):
                with m.If(ability_match):
                    m.d.comb += nxt.eq(_S.AN_ENABLE)
        data_now = self.xmit == Xmit.DATA
        with m.If(self.mr_restart_an | ~self.sync_status | (self.invalid & ~data_now)):
            m.d.comb += nxt.eq(_S.AN_ENABLE)

        # The entry actions of the state entered.
        m.d.sync += state.eq(nxt)
        entering = nxt != state
        with m.If(entering & ((nxt == _S.AN_RESTART) | (nxt == _S.COMPLETE_ACKNOWLEDGE) | (nxt == _S.IDLE_DETECT))):
            m.d.sync += timer.eq(0)
        with m.Elif(~link_timer_done):
            m.d.sync += timer.eq(timer + 1)
        with m.If(entering & (nxt == _S.AN_ENABLE)):
            m.d.sync += self.restarts.eq(self.restarts + 1)
        with m.If(entering & (nxt == _S.COMPLETE_ACKNOWLEDGE)):
            m.d.sync += self.mr_lp_adv_ability.eq(rx_config)
        m.d.sync += self.mr_an_complete.eq(nxt == _S.LINK_OK)
        with m.Switch(nxt):
            with m.Case(_S.AN_ENABLE):
                m.d.sync += [self.xmit.eq(Mux(self.mr_an_enable, Xmit.CONFIGURATION, Xmit.IDLE)),
                             self.tx_config.eq(0)]
            with m.Case(_S.AN_RESTART):
                m.d.sync += [self.xmit.eq(Xmit.CONFIGURATION), self.tx_config.eq(0)]
            with m.Case(_S.ABILITY_DETECT):
                m.d.sync += [self.xmit.eq(Xmit.CONFIGURATION), self.tx_config.eq(self.mr_adv_ability)]
            with m.Case(_S.ACKNOWLEDGE_DETECT, _S.COMPLETE_ACKNOWLEDGE):
                m.d.sync += [self.xmit.eq(Xmit.CONFIGURATION), self.tx_config.eq(self.mr_adv_ability | ACK)]
            with m.Case(_S.IDLE_DETECT):
                m.d.sync += self.xmit.eq(Xmit.IDLE)
            with m.Case(_S.LINK_OK, _S.AN_DISABLE_LINK_OK):
                m.d.sync += self.xmit.eq(Xmit.DATA)
        return m
