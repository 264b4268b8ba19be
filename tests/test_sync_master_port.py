"""The sync master behind its network port: its core's generated Verilog driven over GMII
(:mod:`sim.tb.master_core_tb`), and the parser's checks in Amaranth simulation against the
protocol's reference model."""

import pytest

from gateware.protocol.master import master_config_init
from gateware.registers import TriggerMode
from gateware.top.sync_master import SYNC_HZ, SyncMasterCore
from sim.harness import cocotb_run
from sim.tb.gmii_host import address_value

ADDRESSES = {"mac": "02:44:4d:00:00:f0", "ip": "192.168.1.9", "port": 5000}



@pytest.mark.verilog
@pytest.mark.parametrize("boards", [4, 12])     # four tiles; three groups of four
def test_sync_master_core_over_gmii(boards):
    config = master_config_init(mode=TriggerMode.EXTERNAL, armed=False, period=1000, min_period=400, width=3)
    core = SyncMasterCore(boards, config=config, mac=address_value(ADDRESSES["mac"]), ip=address_value(ADDRESSES["ip"]),
                          port=ADDRESSES["port"], mdio_cycles=(20, 20))
    cocotb_run.run(core, toplevel="sync_master_core", module="sim.tb.master_core_tb", key=str(boards),
                   params={"boards": boards, "clock_hz": int(SYNC_HZ), "config": config, **ADDRESSES})
