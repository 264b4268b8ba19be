"""The DLPC410's rules as formal properties of the sequencer: no command during INIT_ACTIVE, no
clocking pulse while RST_ACTIVE is high, no load of a pulsed block within its settle time, no clear
overlapping a row load.

The top is :class:`gateware.dlpc410.sequencer.Sequencer` on :data:`DMD` (two buses, two DCLK
cycles a row, two blocks of four rows) at one beat, every input free: registers, triggers, the
store's frames, words and occupancy, and the controller's pins, ECP2_FINISHED, INIT_ACTIVE and
RST_ACTIVE included: the controller may start up, initialise again mid-run, and raise or drop
RST_ACTIVE at any time. The phased settle check takes :data:`DMD4` (four blocks of two rows, so
that dual and single modes have two groups or more), a clear check also :data:`DMD_1080P_CLEAR`.

Properties, white box so that k-induction closes (a part's signal is copied out while the
sequencer is elaborated):

* the sequencer drives a command (ROWMD or BLKMD not no-op) only when ECP2_FINISHED was high and
  INIT_ACTIVE low at the pins three cycles earlier (the two cycles of its synchroniser and the
  register of ``running``: the soonest it can know); otherwise only the training pattern is on
  DVALID and the data pins. ``running`` is high exactly when the pins showed the controller
  ready three cycles earlier;
* with the strict reading (``strict_rst``), the bus decides a clocking pulse (on the pins the
  next cycle) only when RST_ACTIVE was low at the pins two cycles earlier (its synchroniser); the
  loose reading lets another group pulse while RST_ACTIVE is high;
* after a clocking pulse, no row load or block clear of a pulsed block reaches the pins before
  ``t_rst + t_settle`` cycles have passed, and, when RST_ACTIVE rises within ``t_rst`` of the
  pulse, none while it is high nor before ``t_settle`` cycles after it fell (bounded: registers
  held, the first load's wait shortened so that pulses and the loads after them are reached).
  Global pulses on :data:`DMD`; quad, dual and single pulses on :data:`DMD4` with the strict
  reading (with the loose one, RST_ACTIVE may be another group's, and a group falls back on
  its planned time: the pin then says nothing of its own reset). The blocks a pulse covers and
  the block a load writes are read from the pins (BLKMD, BLKAD, RST2BLKZ; ROWMD, ROWAD);
* DLPA008B 4.2, as the rule model (:mod:`sim.models.dlpc410_model`) checks it: a row cycle that clears
  a block loads no row, and the ``clear_row_cycles - 1`` row cycles after it (1080p parts) load
  no row, clear no block and pulse not the block being cleared; idle gaps do not count, and a
  controller that initialises again forgets the clear. The sequencer also keeps those no-op
  rows back to back (no idle gap among them), which makes the count inductive.
"""

import dataclasses
from contextlib import contextmanager, nullcontext

from amaranth import Cat, Mux, Signal
from amaranth.hdl import Assert, Assume, Cover, Fragment

from spec.facts import TEST_DMD
from spec.schedule import DECISION_TO_PINS

from .harness import Check, FormalTop
from .stream_properties import stream_rules

__all__ = ["sequencer_checks", "streams_top", "at_beats", "rst_top", "settle_top", "phased_settle_top",
           "clear_top", "DMD", "DMD4", "DMD_1080P_CLEAR"]

#: Two words a row on two buses (two DCLK cycles a row at one beat, the fewest the sequencer
#: takes), eight rows in two blocks: the smallest geometry the sequencer builds for.
DMD = dataclasses.replace(TEST_DMD, name="formal 128x8", rows=8, blocks=2, rows_per_block=4)
#: Four blocks of two rows: two pulse groups in dual mode, four in single mode (one in quad).
DMD4 = dataclasses.replace(DMD, name="formal 128x8, four blocks", blocks=4, rows_per_block=2)
#: The formal DMD with a 1080p clear: the clear's row cycle, then two no-op row cycles.
DMD_1080P_CLEAR = dataclasses.replace(DMD, name="formal 128x8, 1080p clear", clear_row_cycles=3)


@contextmanager
def _watched(part, member, out):
    """While the sequencer is elaborated, its part ``part`` (a class name in
    :mod:`gateware.dlpc410.sequencer`, made inside the sequencer's ``elaborate``) copies its
    member ``member`` (dotted: ``"pulse.valid"``) out to ``out``, for a property."""
    from gateware.dlpc410 import sequencer
    original = getattr(sequencer, part)

    class Watched(original):
        def elaborate(self, platform):
            m = super().elaborate(platform)
            value = self
            for name in member.split("."):
                value = getattr(value, name)
            m.d.comb += out.eq(value)
            return m

    setattr(sequencer, part, Watched)
    try:
        yield
    finally:
        setattr(sequencer, part, original)


def _ready(m, pins, cycles):
    """The controller ready at the pins (ECP2_FINISHED high, INIT_ACTIVE low) on this cycle and on
    each of the ``cycles`` before: a list, this cycle first."""
    history = [pins.ecp2_finished & ~pins.init_active]
    for k in range(cycles):
        earlier = Signal(name=f"ready_{k + 1}")
        m.d.sync += earlier.eq(history[-1])
        history.append(earlier)
    return history


def _row_start(m, pins, length):
    """High on the first cycle of each row cycle on the pins, framed as the controller frames
    them: DVALID high on the cycle's first DCLK edge, ``length`` cycles a row cycle, back to back
    while it stays high (the training pattern is low on that edge)."""
    dvalid = pins.dvalid[0]
    left = Signal(range(length), name="row_left")     # cycles of the row cycle after this one
    start = dvalid & (left == 0)
    with m.If(~dvalid):
        m.d.sync += left.eq(0)
    with m.Elif(start):
        m.d.sync += left.eq(length - 1)
    with m.Else():
        m.d.sync += left.eq(left - 1)
    return start


def _pulsed_blocks(pins, blocks):
    """Per block, whether the command on the pins is a clocking pulse of it (BLKMD 10: block
    BLKAD; 11: global for BLKAD 1xxx, else quad 0qq0 with RST2BLKZ high, dual with it low). An
    encoding the controller rejects is read widely (11xx as global, a quad's low bit ignored):
    the block address rule is not this one."""
    from gateware.dlpc410.interface import BlockMode
    blkad = pins.blkad
    multi = pins.blkmd == BlockMode.MULTI
    return [((pins.blkmd == BlockMode.RESET) & (blkad == b))
            | (multi & (blkad[3] | Mux(pins.rst2blkz, blkad[1:3] == b // 4, blkad[:3] == b // 2)))
            for b in range(blocks)]


def _written_blocks(pins, dmd):
    """Per block, whether the command on the pins writes it: a row load of one of its rows, or a
    clear of it. ROWMD 01 and 11 (the row the pointer holds; the sequencer addresses every row)
    count for every block, an address beyond the array for the last block."""
    from gateware.dlpc410.interface import BlockMode, RowMode
    rowmd, rowad, blkad = pins.rowmd, pins.rowad, pins.blkad
    pointed = (rowmd == RowMode.NEXT) | (rowmd == RowMode.FIRST)
    addressed = rowmd == RowMode.ADDRESSED
    clear = pins.blkmd == BlockMode.CLEAR
    rpb, last = dmd.rows_per_block, dmd.blocks - 1

    def within(value, first, size, block):
        return (value >= first) & ((value < first + size) if block != last else 1)

    return [pointed | (addressed & within(rowad, b * rpb, rpb, b)) | (clear & within(blkad, b, 1, b))
            for b in range(dmd.blocks)]


def _no_command_during_init(running):
    from gateware.dlpc410.interface import BlockMode, RowMode

    def prop(m, top):
        pins = top.dut.pins
        # ready at the pins three cycles ago
        ready_3 = _ready(m, pins, 3)[3]
        command = (pins.rowmd != RowMode.NOOP) | (pins.blkmd != BlockMode.NOOP)
        m.d.comb += [
            Assert(~command | ready_3, "a command while INIT_ACTIVE was high (or ECP2_FINISHED low)"),
            Assert(running == ready_3, "running other than the controller's state three cycles ago"),
        ]
        # the subject: commands once the controller is ready (a command after it initialised
        # again lies past the suite's depth)
        m.d.comb += Cover(command, "a command at the pins")

    return prop


def _no_pulse_while_rst_active(pulse, latency):
    def prop(m, top):
        seen = top.dut.pins.rst_active
        for k in range(latency):
            later = Signal(name=f"rst_{k + 1}")
            m.d.sync += later.eq(seen)
            seen = later
        m.d.comb += Assert(~pulse | ~seen | ~top.dut.regs.strict_rst, "a clocking pulse while RST_ACTIVE was high")
        # the subject: pulses decided under the strict reading, a second one after RST_ACTIVE
        # was high since the first
        strict_pulse = pulse & top.dut.regs.strict_rst
        pulsed, busy_since = Signal(), Signal()
        with m.If(strict_pulse):
            m.d.sync += [pulsed.eq(1), busy_since.eq(0)]
        with m.Elif(pulsed & seen):
            m.d.sync += busy_since.eq(1)
        m.d.comb += [Cover(strict_pulse, "a clocking pulse under the strict reading"),
                     Cover(strict_pulse & busy_since, "a second pulse after RST_ACTIVE was high since the first")]

    return prop


def _settle_environment(m, regs, modes, strict):
    """Registers held from the start, the reset mode one of ``modes``, the strict RST_ACTIVE
    reading if ``strict``, and times not too short for RST_ACTIVE's synchroniser (a real plan's
    are hundreds of cycles)."""
    held, first = Signal.like(regs), Signal(init=1)
    m.d.sync += [held.eq(regs), first.eq(0)]
    m.d.comb += [Assume(first | (regs.as_value() == held.as_value())),
                 Assume(Cat(regs.reset_mode == mode for mode in modes).any()),
                 Assume((regs.t_rst >= 4) & (regs.t_settle >= 4))]
    if strict:
        m.d.comb += Assume(regs.strict_rst)


def _settle_rule(m, regs, rst, pulse, write, extra, name, cover=False):
    """The settle rule of one block: ``pulse`` its clocking pulse's first cycle on the pins,
    ``write`` a row load or clear of it on the pins, ``rst`` RST_ACTIVE at the pins; ``extra``
    cycles claimed beyond ``t_rst + t_settle``."""
    pulsed, rose, fell = (Signal(name=f"{what}_{name}") for what in ("pulsed", "rose", "fell"))
    since_pulse, since_fall = Signal(16, name=f"since_pulse_{name}"), Signal(16, name=f"since_fall_{name}")
    with m.If(pulse):
        m.d.sync += [pulsed.eq(1), since_pulse.eq(1), rose.eq(rst), fell.eq(0)]
    with m.Else():
        with m.If(since_pulse != 2**16 - 1):
            m.d.sync += since_pulse.eq(since_pulse + 1)
        with m.If(pulsed & ~rose & rst & (since_pulse <= regs.t_rst)):
            m.d.sync += rose.eq(1)
        with m.If(rose & ~fell & ~rst):
            m.d.sync += [fell.eq(1), since_fall.eq(1)]
        with m.Elif(fell & (since_fall != 2**16 - 1)):
            m.d.sync += since_fall.eq(since_fall + 1)
    # ``since_*`` counts the cycles after the pulse's first pins cycle (0 on it) and after the
    # fall (0 on the first cycle RST_ACTIVE is low)
    age = Mux(pulse, 0, since_pulse)
    risen = rose | (pulse & rst)
    if cover:
        # the subject: a load after a pulse's settle, right at ``t_rst + t_settle`` (the wait is
        # no longer than the rule asks); a block's second pulse and the load after it lie beyond
        # the depth a bounded check of the sequencer affords
        m.d.comb += [Cover(write & pulsed & ~pulse & (since_pulse == regs.t_rst + regs.t_settle),
                           f"{name}: a load right at t_rst + t_settle after a pulse"),
                     Cover(pulse, f"{name}: a pulse")]
    m.d.comb += [
        Assert(~(write & pulsed) | (age >= regs.t_rst + regs.t_settle + extra),
               "a load sooner than t_rst + t_settle after a pulse"),
        Assert(~(write & risen & ~(fell | (rose & ~rst))), "a load while RST_ACTIVE was high after a pulse"),
        Assert(~(write & fell) | (since_fall >= regs.t_settle), "a load sooner than t_settle after RST_ACTIVE fell"),
    ]


def _settle_after_pulse(pulse, dmd, modes, extra, strict):
    """The settle rule of every block, under the reset ``modes`` (see :func:`_settle_environment`);
    ``pulse``: the bus decides a pulse (on the pins ``DECISION_TO_PINS`` cycles later)."""
    def prop(m, top):
        pins, regs = top.dut.pins, top.dut.regs
        _settle_environment(m, regs, modes, strict)
        on_pins = pulse
        for k in range(DECISION_TO_PINS):
            later = Signal(name=f"pulse_{k + 1}")
            m.d.sync += later.eq(on_pins)
            on_pins = later
        for b, (pulsed, written) in enumerate(zip(_pulsed_blocks(pins, dmd.blocks), _written_blocks(pins, dmd),
                                                  strict=True)):
            _settle_rule(m, regs, pins.rst_active, on_pins & pulsed, written, extra, f"block{b}", cover=b == 0)

    return prop


def _no_clear_overlap(dmd, extra, beats=1):
    """DLPA008B 4.2 as the rule model checks it (see the module's notes); ``extra``: claim this
    many no-op row cycles after a clear more than the DMD takes."""
    from gateware.dlpc410.interface import BlockMode, RowMode
    from spec.schedule import row_cycles

    def prop(m, top):
        pins = top.dut.pins
        # a controller that initialises again forgets the clear under way (as the model does);
        # the pins show the sequencer's commands for three cycles more, unseen by it
        restarting = ~Cat(_ready(m, pins, 3)).all()
        start = _row_start(m, pins, row_cycles(dmd, beats))
        rows = dmd.clear_row_cycles - 1 + extra
        busy = Signal(range(rows + 1))            # no-op row cycles the last clear still takes
        clearing = Signal.like(pins.blkad)        # its block
        load, clear = pins.rowmd != RowMode.NOOP, pins.blkmd == BlockMode.CLEAR
        hits_cleared = Cat(pulsed & (clearing == b)
                           for b, pulsed in enumerate(_pulsed_blocks(pins, dmd.blocks))).any()
        with m.If(restarting):
            m.d.sync += busy.eq(0)
        with m.Elif(start & clear):
            m.d.sync += [busy.eq(rows), clearing.eq(pins.blkad)]
        with m.Elif(start & (busy != 0)):
            m.d.sync += busy.eq(busy - 1)
        m.d.comb += [
            Assert(~(start & clear & load), "a clear in a row cycle that loads a row"),
            Assert(restarting | ~(start & (busy != 0)) | ~(load | clear | hits_cleared),
                   "a row load, clear or pulse of the block within a clear's no-op rows"),
            # (the rows claimed beyond the DMD's may end in a gap: the claim is about loads)
            Assert(restarting | pins.dvalid[0] | (busy <= extra), "an idle gap within a clear's no-op rows"),
        ]
        # the subject: a row load right after a clear's no-op rows (at once after the clear on a
        # one-row clear)
        after = Signal()
        m.d.sync += after.eq(Mux(start, (clear & (rows == 0)) | (~clear & (busy == 1)), after))
        m.d.comb += [Cover(start & clear, "a block clear"),
                     Cover(start & load & after & ~restarting, "a row load right after a clear")]

    return prop


def at_beats(dmd, beats):
    """``dmd`` for ``beats`` DCLK beats a cycle: at two (DCLK 400 MHz, the default build) with
    twice the columns, so that a row cycle takes as many ``dmd`` cycles as ``dmd``'s at one."""
    if beats == 1:
        return dmd
    return dataclasses.replace(dmd, name=f"{dmd.name}, two beats", columns=2 * dmd.columns,
                               visible_columns=2 * dmd.visible_columns, dclk_per_row=2 * dmd.dclk_per_row)


def _sequencer_top(prop, watch=None, *, init_to_dvalid=None, dmd=DMD, beats=1, streams=False):
    """The sequencer on ``dmd`` with ``prop(watched)`` as its property, ``watched`` a copy of the
    member ``member`` of its part ``part`` for ``watch = (part, member)`` (:func:`_watched`);
    ``init_to_dvalid``: a shorter wait before the first load than the facts' 64 clocks, so that a
    bounded check reaches a pulse within a few tens of steps (15 with 2); ``beats``: DCLK beats
    per cycle (the DMD then :func:`at_beats` of ``dmd``); ``streams``: also the stream rules on
    the sequencer's stream ports and between its parts."""
    from gateware.dlpc410 import control
    from gateware.dlpc410.sequencer import Sequencer
    watched = Signal()
    original = control.INIT_TO_DVALID
    control.INIT_TO_DVALID = original if init_to_dvalid is None else init_to_dvalid
    try:
        with _watched(*watch, watched) if watch else nullcontext():
            dut = Sequencer(at_beats(dmd, beats), beats=beats, store_words=1)
            body = Fragment.get(dut, None)          # (its parts made, for the stream rules)
            properties = [prop(watched)]
            if streams:
                # the frame control's flush drops the row source's beats owed to stale loads, a
                # register set applied at rest may change their source (the pattern source's or
                # the store's), and a reseed restarts the pattern source (its word changes two
                # cycles later): resets of its output, as the writer's ``discard`` is of the
                # writer's
                reseeded = Signal()

                def reseed_seen(m, top):
                    m.d.sync += reseeded.eq(top.dut.reseed)
                # a controller that initialises again, a store that lost its memory, or a
                # register set applied (every group's first plane loaded again) stops the groups:
                # the loads under way are dropped, their requests withdrawn
                stopped = ~dut.parts["init"].running | dut.store_lost | dut.reload
                resets = {"row_source": dut.parts["row_source"].flushing | dut.reload | dut.reseed | reseeded,
                          "requester": stopped}
                parts = [(name, part, {}, *([resets[name]] if name in resets else []))
                         for name, part in dut.parts.items()]
                # (a dark pulse's clears come past the check's depth: the darks queue's transfers
                # are not covered)
                properties += [_registers_at_rest, reseed_seen,
                               stream_rules(resets=[stopped], parts=parts, uncovered=("darks",))]
            return Fragment.get(FormalTop(dut, properties, body=body), None)
    finally:
        control.INIT_TO_DVALID = original


def _registers_at_rest(m, top):
    """The sequencer's contract for its registers: they change only while it rests, in the
    cycle ``reload`` says so."""
    regs = top.dut.regs.as_value()
    before, first = Signal.like(regs), Signal(init=1)
    m.d.sync += [before.eq(regs), first.eq(0)]
    m.d.comb += Assume(first | (regs == before) | (top.dut.reload & top.dut.at_rest))


def _init_top(init_to_dvalid=2, beats=1):
    return _sequencer_top(_no_command_during_init, ("Init", "running"), init_to_dvalid=init_to_dvalid, beats=beats)


def streams_top(beats=1, init_to_dvalid=2):
    """The stream rules on the sequencer's ports and between its parts (the planner, the
    queues, the requester, the row source, the bus, the frame control), with covers of
    transfers on each."""
    return _sequencer_top(lambda _: (lambda m, top: None), init_to_dvalid=init_to_dvalid, beats=beats,
                          streams=True)


def rst_top(latency=2, init_to_dvalid=2, beats=1):
    """The RST_ACTIVE property's top; ``latency``: cycles from the pins to the decision it allows
    (the synchroniser's two; one is too few, and the check must then fail)."""
    return _sequencer_top(lambda pulse: _no_pulse_while_rst_active(pulse, latency), ("Bus", "planner.pulsing"),
                          init_to_dvalid=init_to_dvalid, beats=beats)


def settle_top(init_to_dvalid=2, extra=0, beats=1):
    """The settle property's top, global pulses. ``extra``: claim this many cycles more after a
    pulse than the sequencer keeps (1: the check must fail, for the sequencer loads right at
    ``t_rst + t_settle``)."""
    from gateware.registers import ResetMode
    return _sequencer_top(lambda pulse: _settle_after_pulse(pulse, at_beats(DMD, beats), [ResetMode.GLOBAL], extra,
                                                            strict=False),
                          ("Bus", "planner.pulsing"), init_to_dvalid=init_to_dvalid, beats=beats)


def phased_settle_top(modes=("QUAD", "DUAL", "SINGLE"), init_to_dvalid=2, extra=0, strict=True, dmd=DMD4,
                      beats=1):
    """The settle property's top in the phased ``modes`` (names of
    :class:`~gateware.registers.ResetMode`) on ``dmd``; ``extra`` as for :func:`settle_top`;
    ``strict``: the strict RST_ACTIVE reading only."""
    from gateware.registers import ResetMode
    modes = [ResetMode[mode] for mode in modes]
    return _sequencer_top(lambda pulse: _settle_after_pulse(pulse, at_beats(dmd, beats), modes, extra, strict),
                          ("Bus", "planner.pulsing"), init_to_dvalid=init_to_dvalid, dmd=dmd, beats=beats)


def clear_top(dmd=DMD, extra=0, init_to_dvalid=2, beats=1):
    """The clear property's top on ``dmd``. ``extra``: claim one no-op row cycle more after a
    clear than the DMD takes (the check must fail: the sequencer loads right after them)."""
    return _sequencer_top(lambda _: _no_clear_overlap(at_beats(dmd, beats), extra, beats),
                          init_to_dvalid=init_to_dvalid, dmd=dmd, beats=beats)


def sequencer_checks():
    """Every property at one beat (block ``Sequencer``: DCLK 200 MHz) and at two (``Sequencer
    x2``: DCLK 400 MHz, the default build). The suite runs the one-beat proofs; the stream
    rules, the settle checks (their covers from step 31) and the two-beat checks are ``make
    formal``'s."""
    checks = []
    for beats, block in ((1, "Sequencer"), (2, "Sequencer x2")):
        def at(top, beats=beats, **kwargs):
            return lambda: top(beats=beats, **kwargs)

        def suite(depth, beats=beats):
            return depth if beats == 1 else None
        checks += [
            Check("stream rules", block, at(streams_top), depth=24, quick=None),
            Check("no command during INIT_ACTIVE", block, at(_init_top), depth=24, induction=4, quick=suite(24)),
            Check("no clocking pulse while RST_ACTIVE is high", block, at(rst_top), depth=24, induction=4,
                  quick=suite(24)),
            Check("no load within the settle time after a pulse and after RST_ACTIVE fell", block,
                  at(settle_top), depth=40, quick=None),
            Check("no load of a pulsed group within its settle time, phased modes", block,
                  at(phased_settle_top), depth=40, quick=None),
            Check("no clear overlapping a row load", block, at(clear_top), depth=24, induction=4, quick=suite(24)),
            Check("no clear overlapping a row load, 1080p clear", block, at(clear_top, dmd=DMD_1080P_CLEAR),
                  depth=24, induction=6, quick=suite(24))]
    return checks
