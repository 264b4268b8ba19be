"""cocotb testbench: the sync master's core (:class:`gateware.top.sync_master.SyncMasterCore`,
generated Verilog) as a virtual sync master on a TAP interface (:mod:`sim.rigs.virtual_run` makes
the namespace and the TAP; the frames cross as :func:`sim.tb.virtual_projector_tb.bridge` carries
them). Every board is ready; the pulses on the sync and camera lines are read every cycle
(:class:`sim.tb.master_core_tb.Pulses`: all at once, each as long as the others) and reported with
their lengths when the run stops.

Run by :func:`sim.rigs.virtual_run.master_demo` and so by ``tests/test_virtual_projector.py``.
"""

import json
from pathlib import Path

import cocotb

from sim.harness.cocotb_run import params
from sim.tb.gmii_host import GmiiHost
from sim.tb.master_core_tb import start
from sim.tb.virtual_projector_tb import bridge


@cocotb.test()
async def virtual_master(dut):
    p = params()
    host = GmiiHost(dut, p["mac"], p["ip"], p["port"])
    pulses = await start(dut, host, p["boards"])
    report = await bridge(dut, host, p)
    Path(p["report"]).write_text(json.dumps({**report, "pulses": len(pulses.starts), "widths": pulses.widths}))
