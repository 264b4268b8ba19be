"""The system run's Verilog memory model against the Python MCB model: same data, same rules,
on a 64-bit and a 128-bit port (each case's first rule broken on port 0, the second on port 1),
and through a calibration loss (:mod:`sim.tb.mcb_model_tb`)."""

import pytest

from sim.harness import cocotb_run
from sim.harness.paths import ROOT
from sim.models import mcb_client

SOURCE = ROOT / "sim" / "hdl" / "mcb_model.v"


def run(testcase, plusargs=(), **params):
    cocotb_run.run(None, toplevel="mcb_model", module="sim.tb.mcb_model_tb", key="default", testcase=testcase,
                   extra_sources=[SOURCE], params=params, plusargs=plusargs)


@pytest.mark.verilog
def test_traffic_agrees_with_python_model():
    run("client_traffic_agrees")


@pytest.mark.verilog
@pytest.mark.parametrize("case", [("before_calib", "misaligned"), ("misaligned", "out_of_range"),
                                  ("data_missing", "wr_full"), ("rd_empty", "overflow"), ("cmd_full", "cmd_full")],
                         ids="-".join)
def test_rule_breaks_agree_with_python_model(case):
    run("scripted_rule_breaks", case=list(case))


@pytest.mark.verilog
@pytest.mark.parametrize("case", [("read_lost", "rewrite"), ("rewrite", "before_calib"), ("before_calib", "read_lost")],
                         ids="-".join)
def test_calibration_loss_agrees_with_python_model(case):
    run("calibration_loss", plusargs=mcb_client.loss_plusargs(), case=list(case))


@pytest.mark.verilog
def test_read_after_idle_agrees_with_python_model():
    run("read_after_idle")
