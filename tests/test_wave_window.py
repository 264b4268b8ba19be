"""The wave window of ``make sim WINDOW=1`` (``sim/hdl/wave_window.v``) on a small design built as
the XGA run's window build is (tracing, the DPI close): the dump holds value changes only while the
window is open, every signal inside the design included, and the save file made for it
(:func:`sim.rigs.system_run.window_groups`) names only signals the dump declares. The testbench:
:mod:`sim.tb.wave_window_tb`."""

import re

import pytest
from amaranth import ClockDomain, ClockSignal, Instance, Module, Signal
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from sim.harness import cocotb_run
from sim.harness.paths import build_dir
from sim.harness.waves import declared
from sim.rigs import system_run as system
from sim.rigs.fast_system_rig import PLUSARGS, WINDOW_SOURCES

OPEN_NS, CLOSE_NS = 200, 500


class _Bus(wiring.Component):
    """A block with state of its own, as the core's ``sequencer.bus``."""

    count: Out(8)

    def elaborate(self, platform):
        m = Module()
        inner = Signal(16)
        m.d.sync += [inner.eq(inner + 3), self.count.eq(inner[2:])]
        return m


class WindowRig(wiring.Component):
    """A clock, two of the core's pins and a block under ``sequencer``, with the wave window."""

    clk: In(1)
    wave_dump: In(1)
    dlpc__dvalid: Out(2)
    sync_out: Out(1)

    def elaborate(self, platform):
        m = Module()
        m.domains.sync = ClockDomain(reset_less=True)
        m.d.comb += ClockSignal("sync").eq(self.clk)
        sequencer = Module()
        sequencer.submodules.bus = bus = _Bus()
        m.submodules.sequencer = sequencer
        m.d.comb += [self.dlpc__dvalid.eq(bus.count[:2]), self.sync_out.eq(bus.count[7])]
        m.submodules.wave_window = Instance("wave_window", i_dump=self.wave_dump)
        return m


@pytest.mark.verilog
def test_window_dumps_only_while_open_and_save_file_names_exist():
    directory = build_dir("wave_window", "run")
    vcd = directory / "window.vcd"
    vcd.unlink(missing_ok=True)
    cocotb_run.run(WindowRig(), toplevel="window_rig", module="sim.tb.wave_window_tb", key="window",
                   params={"open_ns": OPEN_NS, "close_ns": CLOSE_NS}, extra_sources=WINDOW_SOURCES,
                   plusargs=[f"+{PLUSARGS['window']}={vcd}"], traced=True, run_dir=directory)
    text = vcd.read_text()
    times = [int(t) for t in re.findall(r"^#(\d+)$", text, re.M)]
    # the clock runs for 3 windows' length; the dump holds the open one only (ps)
    assert times and OPEN_NS * 1000 <= min(times) and max(times) < CLOSE_NS * 1000, (times[0], times[-1])
    assert len(times) >= (CLOSE_NS - OPEN_NS) // 10, "every edge in the window is there"
    scopes = declared(vcd)
    assert any(name.startswith("inner") for name in scopes["window_rig.sequencer.bus"]), \
        "signals inside the design are dumped, not only ports"
    groups = system.window_groups(vcd, core="window_rig")
    assert groups["sequencer: bus"] and groups["DLPC410 pins, trigger, sync and camera"] == \
        ["dlpc__dvalid[1:0]", "sync_out"]
    save = system.write_save_file(vcd, groups, "window_rig", view=(OPEN_NS * 1000, CLOSE_NS * 1000),
                                  markers={"trigger": 300_000})
    everything = {f"{scope}.{name}" for scope, names in scopes.items() for name in names}
    traced = [line.strip() for line in save.read_text().splitlines() if line.startswith("window_rig.")]
    assert traced and set(traced) <= everything, set(traced) - everything
