"""Formal checks (SymbiYosys, Yices, from PyPI) within the suite's budget: the harness catches
what it must, a proof closes, the store's properties and the frame slots' streams hold to a
short depth. ``make formal`` runs every property at its full depth."""

import dataclasses

import pytest
from amaranth import Module, Signal
from amaranth.lib import stream, wiring
from amaranth.lib.wiring import In, Out

from sim.formal import blocks, sequencer, store
from sim.formal.harness import Check, FormalFailure, FormalTop, run
from sim.formal.streams import ready_paths, stream_rules
from sim.harness.paths import build_dir


class Dropper(wiring.Component):
    """Offers a count every fourth cycle for one cycle, whether taken or not: breaks the rule."""
    o: Out(stream.Signature(8))

    def elaborate(self, platform):
        m = Module()
        count = Signal(8)
        m.d.sync += count.eq(count + 1)
        m.d.comb += [self.o.valid.eq(count[:2] == 3), self.o.payload.eq(count)]
        return m


class Register(wiring.Component):
    """A one-place register slice; ``leak`` makes its output valid wait for ready."""
    i: In(stream.Signature(8))
    o: Out(stream.Signature(8))

    def __init__(self, leak=False):
        self._leak = leak
        super().__init__()

    def elaborate(self, platform):
        m = Module()
        full = Signal()
        m.d.comb += [self.o.valid.eq(full & (self.o.ready if self._leak else 1)),
                     self.i.ready.eq(~full | self.o.ready)]
        with m.If(self.i.valid & self.i.ready):
            m.d.sync += [self.o.payload.eq(self.i.payload), full.eq(1)]
        with m.Elif(self.o.ready):
            m.d.sync += full.eq(0)
        return m


def _check(name, make, **kwargs):
    return Check("stream rules", name, lambda: FormalTop(make(), [stream_rules()]), **kwargs)


def test_broken_stream_fails_with_a_counterexample():
    with pytest.raises(FormalFailure) as failure:
        run(_check("Dropper", Dropper, depth=10))
    result = failure.value.result
    assert "o: valid fell before the transfer" in result.failed
    assert result.vcd is not None and result.vcd.exists()


def test_register_slice_is_proven():
    result = run(_check("Register", Register, depth=10, induction=2))
    assert result.status == "proven" and result.depth == 2


class Wire(wiring.Component):
    """Input to output, combinationally: it keeps the rules exactly when its producer does."""
    i: In(stream.Signature(8))
    o: Out(stream.Signature(8))

    def elaborate(self, platform):
        m = Module()
        wiring.connect(m, wiring.flipped(self.i), wiring.flipped(self.o))
        return m


def test_input_rules_are_assumed():
    assert run(_check("Wire", Wire, depth=6, induction=1)).status == "proven"
    free_input = Check("stream rules", "Wire-free-input",
                       lambda: FormalTop(Wire(), [stream_rules(exclude=("i",))]), depth=6)
    with pytest.raises(FormalFailure):
        run(free_input)


def test_ready_paths():
    assert ready_paths(Register(), build_dir("formal", "test-ready-good")) == {}
    assert ready_paths(Register(leak=True), build_dir("formal", "test-ready-leak")) == {"o__valid": ["o__ready"]}


@pytest.mark.parametrize("check", [
    *[c for c in blocks.checks() if c.block in ("Countdown", "SlotStates", "SyncMaster")],
    *[c for c in store.store_checks()],
], ids=lambda c: c.key)
def test_checks_quick(check):
    result = run(dataclasses.replace(check, induction=None), depth=check.quick)
    assert result.status in ("proven", "checked")


@pytest.mark.parametrize("check", blocks.stream_checks(), ids=lambda c: c.block)
def test_stream_rules_of_every_block(check):
    """The stream rules of every block with stream ports: proven where a proof closes, else
    checked to the block's test depth (20 steps: the transmitter's header changing with the
    addresses failed at step 9, the transmit crossing offering a frame too soon after a frame
    longer than its FIFO at step 19); and no output ``valid`` waits combinationally for a
    ``ready``."""
    assert run(check, depth=check.quick).status in ("proven", "checked")
    block = next(b for b in blocks.STREAM_BLOCKS if b.name == check.block)
    assert ready_paths(block.make(), build_dir("formal", f"test-ready-{check.block}")) == {}


class Through(wiring.Component):
    """A synchroniser without its flip-flops: the sequencer then sees the pins two cycles early."""

    def __init__(self, i, o, **kwargs):
        self._i, self._o = i, o
        super().__init__({})

    def elaborate(self, platform):
        m = Module()
        m.d.comb += self._o.eq(self._i)
        return m


def _sequencer_check(name):
    return next(check for check in sequencer.sequencer_checks() if check.name == name)


def test_sequencer_init_rule(monkeypatch):
    from gateware.dlpc410 import init
    check = _sequencer_check("no command during INIT_ACTIVE")
    assert run(check).status == "proven"
    monkeypatch.setattr(init, "FFSynchronizer", Through)
    with pytest.raises(FormalFailure) as failure:
        run(dataclasses.replace(check, block="Sequencer-unsynchronised"))
    assert "running other than the controller's state three cycles ago" in failure.value.result.failed


def test_sequencer_rst_active_rule():
    """Proven; and not vacuous: claimed one cycle sooner than the synchroniser allows, it fails
    (a pulse is reached with RST_ACTIVE rising just before it)."""
    check = _sequencer_check("no clocking pulse while RST_ACTIVE is high")
    assert run(check).status == "proven"
    with pytest.raises(FormalFailure) as failure:
        run(dataclasses.replace(check, block="Sequencer-rst-one-cycle", induction=None,
                                build=lambda: sequencer.rst_top(latency=1, init_to_dvalid=2)), depth=24)
    assert "a clocking pulse while RST_ACTIVE was high" in failure.value.result.failed


def _first_failure(check, build, depth):
    """The failure of ``check`` with the property ``build`` makes (a claim stronger than the
    check's), within ``depth`` steps."""
    with pytest.raises(FormalFailure) as failure:
        run(dataclasses.replace(check, block=f"{check.block}-stronger", build=build), depth=depth)
    return failure.value.result


# A claim one cycle stronger than the sequencer keeps fails, so the check is not vacuous; and as a
# bounded check stops at the first step where any assertion fails, and the stronger claim fails
# wherever the real one does, the step it fails at (on its strengthened assertion only) shows the
# real claim holding at every step before it.

def test_sequencer_settle_rule():
    """The real claim holds at every step before 31 (past the suite's depth of the check): claimed
    one cycle longer after a pulse than the sequencer waits, it fails at step 31 (a load right at
    ``t_rst + t_settle`` after a pulse)."""
    check = _sequencer_check("no load within the settle time after a pulse and after RST_ACTIVE fell")
    result = _first_failure(check, lambda: sequencer.settle_top(extra=1), 32)
    assert result.failed == ["a load sooner than t_rst + t_settle after a pulse"]
    assert result.step == 31 and result.step > check.quick, result.step


@pytest.mark.parametrize("dmd", [sequencer.DMD, sequencer.DMD_1080P_CLEAR], ids=["one-row-clear", "1080p-clear"])
def test_sequencer_clear_rule(dmd):
    """Proven; and not vacuous: claimed one no-op row cycle longer than the DMD takes, it fails (a
    second clear right after a clear, at step 19; on the 1080p clear a row load right after the
    two no-op rows, at step 23)."""
    name = "no clear overlapping a row load" + (", 1080p clear" if dmd.clear_row_cycles > 1 else "")
    check = _sequencer_check(name)
    assert run(check).status == "proven"
    with pytest.raises(FormalFailure) as failure:
        run(dataclasses.replace(check, block="Sequencer-clear-one-more", induction=None,
                                build=lambda: sequencer.clear_top(dmd, extra=1)), depth=24)
    assert failure.value.result.failed == ["a row load, clear or pulse of the block within a clear's no-op rows"]
    assert failure.value.result.step == (23 if dmd.clear_row_cycles > 1 else 19)


def test_sequencer_phased_settle_rule():
    """The real claim holds at every step before 35 (past the suite's depth of the check): claimed
    one cycle longer after a pulse than the sequencer waits, it fails at step 35 (a load of a
    pulsed group right at ``t_rst + t_settle`` after its pulse)."""
    check = _sequencer_check("no load of a pulsed group within its settle time, phased modes")
    result = _first_failure(check, lambda: sequencer.phased_settle_top(extra=1), 36)
    assert result.failed == ["a load sooner than t_rst + t_settle after a pulse"]
    assert result.step == 35 and result.step > check.quick, result.step


def test_slot_states_last_write_wins_is_proven():
    """The sequence slots' states (two writers built of one-writer memories, XOR halves): each
    slot reads what was last written to it, by k-induction."""
    check = blocks.slot_states_check()
    assert run(check, depth=check.depth).status == "proven"
