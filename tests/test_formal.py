"""Formal checks (SymbiYosys, Yices, from PyPI): the harness catches what it must (a broken rule,
a cover not reached, a property without a cover), every property with a suite depth holds there
with its covers reached, and each sequencer rule fails against a claim the sequencer must break.

The harness's own tests run in ``make test``. The properties and the sequencer's failing claims
(marked ``formal``) run in ``make properties``, which CI runs after ``make test``: together they
take as long as the rest of the suite. ``make formal`` runs every property at its full depth."""

import dataclasses

import pytest
from amaranth import Module, Signal
from amaranth.hdl import Assert, Cover
from amaranth.lib import stream, wiring
from amaranth.lib.wiring import In, Out

from sim.formal import block_properties as blocks
from sim.formal import sequencer_properties as sequencer
from sim.formal import suite
from sim.formal.harness import Check, FormalFailure, FormalTop, run
from sim.formal.stream_properties import ready_paths, stream_rules
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


def _suite_checks():
    """Every property ``make formal`` lists that the suite runs too (those with a suite depth);
    the others are deep checks of ``make formal`` alone."""
    return [check for check in suite.checks() if check.quick is not None]


@pytest.mark.formal
@pytest.mark.parametrize("check", _suite_checks(), ids=lambda c: c.key)
def test_property(check):
    """Proven (k-induction) or checked to the suite's depth, and every cover of what the property
    is about reached within that depth (else the run fails: a bounded check that never meets its
    subject proves nothing)."""
    result = run(check if check.quick_proof else dataclasses.replace(check, induction=None), depth=check.quick)
    assert result.status in ("proven", "checked")
    assert result.covers and not result.unreached


@pytest.mark.parametrize("block", blocks.STREAM_BLOCKS, ids=lambda b: b.name)
def test_no_valid_waits_for_ready(block):
    """No output ``valid`` of a block with stream ports waits combinationally for a ``ready``."""
    assert ready_paths(block.make(), build_dir("formal", f"test-ready-{block.name}")) == {}


class Unreachable(wiring.Component):
    """A counter that never passes 3: a cover of 5 cannot be reached."""
    count: Out(4)

    def elaborate(self, platform):
        m = Module()
        with m.If(self.count != 3):
            m.d.sync += self.count.eq(self.count + 1)
        return m


def test_a_cover_not_reached_fails_the_check():
    def prop(m, top):
        m.d.comb += [Assert(top.dut.count <= 3, "at most 3"), Cover(top.dut.count == 3, "three"),
                     Cover(top.dut.count == 5, "five")]
    check = Check("covers", "Unreachable", lambda: FormalTop(Unreachable(), [prop]), depth=8, induction=2)
    with pytest.raises(FormalFailure) as failure:
        run(check)
    result = failure.value.result
    assert result.covers == {"three": 3, "five": None}
    assert result.failed == ["cover not reached within 8 steps: five"]


def test_a_property_without_a_cover_fails_the_check():
    def prop(m, top):
        m.d.comb += Assert(top.dut.count <= 3, "at most 3")
    check = Check("no cover", "Unreachable", lambda: FormalTop(Unreachable(), [prop]), depth=6, induction=2)
    with pytest.raises(FormalFailure) as failure:
        run(check)
    assert failure.value.result.failed == ["no cover of the property's subject"]


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


# Each sequencer rule against a claim the sequencer must break (its proof and covers run in
# test_property): the check fails, so it is not vacuous, and the bound it keeps is exact.

@pytest.mark.formal
def test_sequencer_init_rule_without_its_synchroniser_fails(monkeypatch):
    from gateware.dlpc410 import init
    check = _sequencer_check("no command during INIT_ACTIVE")
    monkeypatch.setattr(init, "FFSynchronizer", Through)
    with pytest.raises(FormalFailure) as failure:
        run(dataclasses.replace(check, block="Sequencer-unsynchronised"))
    assert "running other than the controller's state three cycles ago" in failure.value.result.failed


@pytest.mark.formal
def test_sequencer_rst_active_rule_one_cycle_sooner_fails():
    """Claimed one cycle sooner than the synchroniser allows, it fails (a pulse is reached with
    RST_ACTIVE rising just before it)."""
    check = _sequencer_check("no clocking pulse while RST_ACTIVE is high")
    with pytest.raises(FormalFailure) as failure:
        run(dataclasses.replace(check, block="Sequencer-rst-one-cycle", induction=None,
                                build=lambda: sequencer.rst_top(latency=1, init_to_dvalid=2)), depth=24)
    assert "a clocking pulse while RST_ACTIVE was high" in failure.value.result.failed


@pytest.mark.formal
@pytest.mark.parametrize("dmd", [sequencer.DMD, sequencer.DMD_1080P_CLEAR], ids=["one-row-clear", "1080p-clear"])
def test_sequencer_clear_rule_one_row_more_fails(dmd):
    """Claimed one no-op row cycle longer than the DMD takes, it fails (a second clear right after
    a clear, at step 19; on the 1080p clear a row load right after the two no-op rows, at step
    23)."""
    name = "no clear overlapping a row load" + (", 1080p clear" if dmd.clear_row_cycles > 1 else "")
    check = _sequencer_check(name)
    with pytest.raises(FormalFailure) as failure:
        run(dataclasses.replace(check, block="Sequencer-clear-one-more", induction=None,
                                build=lambda: sequencer.clear_top(dmd, extra=1)), depth=24)
    assert failure.value.result.failed == ["a row load, clear or pulse of the block within a clear's no-op rows"]
    assert failure.value.result.step == (23 if dmd.clear_row_cycles > 1 else 19)


def test_a_check_that_does_not_end_is_a_failed_row(monkeypatch):
    """``make formal`` goes on past a check that runs out of time, and counts it failed."""
    import subprocess

    def never_ends(check, **_kwargs):
        raise subprocess.TimeoutExpired(["sby"], 3600)
    monkeypatch.setattr(suite, "run", never_ends)
    row = suite._check_row(0, quick=False)
    assert row.status == "failed" and "3600 s" in row.detail
    assert suite.figures([row])["formal.properties_failed"][0] == 1
