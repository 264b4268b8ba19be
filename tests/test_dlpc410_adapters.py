"""Both adapters of the DLPC410 model: the Amaranth simulator process and the cocotb coroutine on
the generated Verilog, each fed by the replay component, agree with the model fed directly (the
cocotb side's testbench: :mod:`sim.tb.dlpc410_replay_tb`)."""

import numpy as np
import pytest

from sim.harness import cocotb_run
from sim.harness.amaranth_sim import simulate
from sim.models.dlpc410_model import RULES, Dlpc410, RuleBreak, amaranth_process
from sim.models.dlpc410_replay import MODEL_PARAMS, NAMES, replay, sequences
from spec.facts import TEST_DMD

SEQUENCES = sequences(TEST_DMD)


def reference(name):
    model = Dlpc410(TEST_DMD, **MODEL_PARAMS)
    try:
        model.run(SEQUENCES[name])
    except RuleBreak as e:
        return model, e
    return model, None


def run_amaranth(name, test_name):
    dut = replay()
    model = Dlpc410(TEST_DMD, **MODEL_PARAMS)

    async def bench(ctx):
        ctx.set(dut.select, NAMES.index(name))
        while not ctx.get(dut.done):
            await ctx.tick()
        await ctx.tick().repeat(4)

    simulate(dut, [bench], name=test_name, processes=[amaranth_process(model, dut.dlpc)],
             deadline=1e-4)
    return model


def test_amaranth_adapter_legal(test_name):
    model = run_amaranth("legal", test_name)
    want, error = reference("legal")
    assert error is None
    assert model.log and model.log == want.log and model.arstz_rise == want.arstz_rise
    assert np.array_equal(model.mirrors, want.mirrors)
    assert [c.mode for c in model.log if c.kind == "pulse"] == ["global", "single", "dual"]
    # the rows the sequence loaded reached the mirrors of block 1; block 2 was cleared
    assert not model.mirrors[48:72].any() and model.mirrors[24:48].any()


def test_amaranth_adapter_illegal(test_name):
    _, want = reference("illegal")
    assert want is not None and want.rule is RULES["rst_active"]
    with pytest.raises(RuleBreak) as info:
        run_amaranth("illegal", test_name)
    assert info.value.rule is RULES["rst_active"] and info.value.cycle == want.cycle


def test_amaranth_adapter_drives_outputs(test_name):
    """INIT_ACTIVE and RST_ACTIVE reach the DUT's ports on the cycles the model says."""
    dut = replay()
    model = Dlpc410(TEST_DMD, **MODEL_PARAMS)
    seen = []

    async def bench(ctx):
        async for _clk, _rst, init, rst, ecp2 in ctx.tick().sample(
                dut.dlpc.init_active, dut.dlpc.rst_active, dut.dlpc.ecp2_finished):
            seen.append((init, rst, ecp2))
            if len(seen) == 300:
                return

    simulate(dut, [bench], name=test_name, processes=[amaranth_process(model, dut.dlpc)], waves=False)
    pulse = next(c.cycle for c in model.log if c.kind == "pulse")
    init = [s[0] for s in seen]
    rst = [s[1] for s in seen]
    assert init.index(0) == model.init_end
    high = list(range(pulse + 1, pulse + 1 + MODEL_PARAMS["rst_active_cycles"]))
    assert [i for i, v in enumerate(rst) if v] == high
    assert seen[-1][2] == 1


@pytest.mark.verilog
def test_cocotb_adapter():
    cocotb_run.run(replay(), toplevel="dlpc410_replay", module="sim.tb.dlpc410_replay_tb", key="test",
                   params={"dmd": "test"})


def test_cocotb_adapter_names():
    """The prefix and the name map pick the DUT's signals; absent members are left out."""
    from types import SimpleNamespace

    from sim.models.dlpc410_model import CocotbAdapter

    dut = SimpleNamespace(**{name: object() for name in
                             ["top_din_a", "top_din_b", "top_dvalid", "dmd_arstz", "top_rst_active"]})
    adapter = CocotbAdapter(Dlpc410(TEST_DMD), dut, clock=None, prefix="top_", names={"arstz": "dmd_arstz"})
    assert [n for n, _ in adapter.inputs] == ["din_a", "din_b", "dvalid", "arstz"]
    assert adapter.inputs[-1][1] is dut.dmd_arstz
    assert [n for n, _ in adapter.outputs] == ["rst_active"]
