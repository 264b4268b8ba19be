"""PHY management: reset, then status polls over MDIO, against the clause-22 PHY model; on the
generated Verilog, :mod:`sim.tb.mdio_tb`."""

import pytest

from gateware.mac.mdio import StatusPoller
from sim.harness.amaranth_sim import simulate
from sim.models.mdio_phy_model import MdioError, MdioPhy

LINK_1000 = (0b10 << 14) | (1 << 11) | (1 << 10)
LINK_DOWN = 0


def run_poller(status_word, name, polls=2, address=7, phy_address=7):
    dut = StatusPoller(125e6, phy_address=address, reset_cycles=40, settle_cycles=10)
    phy = MdioPhy(phy_address, {17: status_word})
    seen = {}

    async def bench(ctx):
        cycles = 0
        reset_low = 0
        while ctx.get(dut.status.polls) < polls:
            level = phy.step(ctx.get(dut.mdc), ctx.get(dut.mdio_o), ctx.get(dut.mdio_oe))
            ctx.set(dut.mdio_i, level)
            reset_low += not ctx.get(dut.phy_reset_n)
            await ctx.tick()
            cycles += 1
            assert cycles < 20000, "no status poll completed"
        seen["status"] = {k: ctx.get(getattr(dut.status, k)) for k in ("up", "speed", "resolved", "polls")}
        seen["reset_low"] = reset_low

    simulate(dut, [bench], name=name)
    return seen, phy


def test_link_up_at_1000(test_name):
    seen, phy = run_poller(LINK_1000, test_name)
    assert seen["status"] == {"up": 1, "speed": 2, "resolved": 1, "polls": 2}
    assert phy.reads == [(7, 17), (7, 17)]
    assert seen["reset_low"] == 41     # the reset wait, then released before the first frame


def test_link_down(test_name):
    seen, _ = run_poller(LINK_DOWN, test_name)
    assert seen["status"]["up"] == 0 and seen["status"]["polls"] == 2


def test_wrong_address_reads_all_ones(test_name):
    """No PHY answers: the bus floats high, so the status shows what all ones decode to and the
    model records no read."""
    seen, phy = run_poller(LINK_1000, test_name, address=3, phy_address=7)
    assert phy.reads == []
    assert seen["status"] == {"up": 1, "speed": 3, "resolved": 1, "polls": 2}


def test_model_rejects_short_preamble():
    phy = MdioPhy(7, {})
    mdc = 0
    with pytest.raises(MdioError, match="preamble of 5 ones"):
        for level in [1] * 5 + [0]:
            for mdc in (0, 1):
                phy.step(mdc, level, 1)


@pytest.mark.verilog
def test_mdio_verilog():
    from sim.harness import cocotb_run
    cocotb_run.run(StatusPoller(125e6, phy_address=7, reset_cycles=40, settle_cycles=10),
                   toplevel="mdio_status_poller", module="sim.tb.mdio_tb", key="atlys",
                   params={"phy_address": 7, "status_word": LINK_1000, "polls": 3})
