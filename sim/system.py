"""``make sim``: the projector's core end to end on the default scene.

The core's generated Verilog (MAC, network stack, protocol, serialiser, store, sequencer) runs
under Verilator with the MCB model on both memory ports and the rule-checking DLPC410 model on
the DMD pins. The default scene is encoded by the host encoder, sent over GMII, triggered, and
the camera model's image is compared with what was sent.

Geometry: the small test DMD (128x96, 4 blocks), with RST_ACTIVE and settle scaled down so that
a run takes a few minutes; the full-XGA system run needs the GMII replay path wired in (the
stimulus is driven from Python here) and is still to come.
"""

import json
import os
import time
from pathlib import Path

from gateware.dlpc410 import schedule
from gateware.dlpc410.facts import DMDS
from gateware.dlpc410.params import PlaneOrder, ResetMode
from gateware.top.system import Projector
from sim.harness import cocotb_run
from sim.harness.paths import build_dir

__all__ = ["main", "run", "plan", "power_up_plan", "PARAMS"]

MAC, IP, PORT = 0x02_00_00_00_00_01, 0x0A_00_00_02, 5000
DMD_NS = 5.0

#: The system run's parameters (the testbench's ``params()``).
PARAMS = {"dmd": "test", "mac": "02:00:00:00:00:01", "ip": "10.0.0.2", "port": PORT,
          "memory_bytes": 4 * 2**20, "t_rst": 40, "t_settle": 60, "init_cycles": 200,
          "init_grace": 4, "mode": "GLOBAL", "order": "MSB_FIRST", "frames": 3, "seed": 1,
          "settle_after_send": 3000, "faults": True}


def plan(p, **changes):
    """The schedule a run configures through a sequencer record: ``p``'s DMD, scaled RST_ACTIVE
    and settle times, reset mode and plane order (``changes``: other :func:`schedule.plan`
    arguments)."""
    kwargs = dict(t_rst_s=p["t_rst"] * DMD_NS * 1e-9, t_settle_s=p["t_settle"] * DMD_NS * 1e-9, depth=8,
                  reset_mode=ResetMode[p["mode"]], order=PlaneOrder[p["order"]])
    return schedule.plan(DMDS[p["dmd"]], 1e9 / DMD_NS, **{**kwargs, **changes})


def power_up_plan(p):
    """The registers the core is built with: planes three times as long as the run's, so that a
    frame shown before the run's sequencer record is applied would not be the frame sent."""
    return plan(p, exposure_s=3 * plan(p).params.lsb * DMD_NS * 1e-9)


def run(key="test", **overrides):
    """Build and run the system testbench; returns its report (dict)."""
    report = build_dir("system") / f"{key}.json"
    p = {**PARAMS, **overrides, "report": str(report)}
    dmd = DMDS[p["dmd"]]
    # built as the platform is: disarmed, the testbench configures and arms through records
    core = Projector(dmd, mac=MAC, ip=IP, port=PORT, regs=power_up_plan(p).params.registers(dmd),
                     armed=False, mdio_cycles=(40, 10))
    build = cocotb_run.run(core, toplevel="projector", module="sim.tb.system", key=key, params=p)
    result = json.loads(report.read_text())
    result["build"] = str(build)
    return result


def main(frames=None):
    dmd = DMDS[PARAMS["dmd"]]
    print(f"make sim: the projector's core (generated Verilog, Verilator) on the default scene, "
          f"{dmd.columns}x{dmd.rows} 8-bit ({dmd.name}); MCB model on both memory ports; "
          f"rule-checking DLPC410 model and camera model on the DMD side")
    os.environ.setdefault("WAVES", "1")
    t0 = time.monotonic()
    r = run("scene", scene=True, frames=frames or PARAMS["frames"])
    frames_out = r["frames"]
    latencies = [f["latency_cycles"] for f in frames_out]
    print()
    status = r["status"]
    dropped = {k: v for k, v in status.items()
               if k.startswith(("drop_", "mac_")) and k != "mac_good" and v}
    print(f"frames shown: {len(frames_out)}; GMII frames sent: {r['gmii_frames_sent']}, received good "
          f"{status['mac_good']}, accepted {status['accepted']}; dropped (status reply): {dropped or 'none'}")
    print(f"trigger to first clocking pulse: typical {sorted(latencies)[len(latencies) // 2]} cycles, "
          f"worst {max(latencies)} cycles ({max(latencies) * DMD_NS:.0f} ns at DCLK = 200 MHz); "
          f"to the optical change add RST_ACTIVE ({PARAMS['t_rst']} cycles here, 908 at TI timing)")
    print(f"frame period: {r['period_cycles']} cycles = {r['rate_hz']:.0f} Hz with the scaled timing "
          f"(schedule model's bound; the gateware equals it cycle for cycle)")
    print(f"grey error of the reconstructed image: max {max(f['max_error_lsb'] for f in frames_out):g} LSB")
    print(f"simulation speed: {r['dmd_cycles'] / r['wall_s']:.0f} dmd cycles per wall second "
          f"({r['dmd_cycles']} cycles in {r['wall_s']:.1f} s)")
    print(f"wall time: {time.monotonic() - t0:.1f} s including the Verilator build")
    vcd = Path(r["build"]) / "dump.vcd"
    if vcd.exists():
        print(f"waves: {vcd}\n  GTKWave save file (ports grouped by block): {write_save_file(vcd)}")
    return 0 if all(f["max_error_lsb"] == 0 for f in frames_out) else 1


#: The core's ports by the block they belong to, for the GTKWave save file.
SAVE_GROUPS = {
    "clocks and resets": ["clk", "rst", "gmii_rx_clk", "gmii_tx_clk", "dmd_clk", "dmd_rst"],
    "MAC: GMII": ["gmii_rx[9:0]", "gmii_tx[9:0]"],
    "store: MCB port 0 (write, sync)": ["mcb_write__cmd_en", "mcb_write__cmd_instr[2:0]", "mcb_write__cmd_bl[5:0]",
                                        "mcb_write__cmd_byte_addr[29:0]", "mcb_write__wr_en",
                                        "mcb_write__wr_data[63:0]", "mcb_write__wr_count[6:0]"],
    "store: MCB port 1 (read, dmd)": ["mcb_read__cmd_en", "mcb_read__cmd_byte_addr[29:0]", "mcb_read__rd_en",
                                      "mcb_read__rd_data[63:0]", "mcb_read__rd_count[6:0]"],
    "sequencer: trigger and sync": ["trigger_in", "sync_out", "camera_out"],
    "sequencer: DLPC410 pins": ["dlpc__dvalid", "dlpc__rowmd[1:0]", "dlpc__rowad[10:0]", "dlpc__blkmd[1:0]",
                                "dlpc__blkad[3:0]", "dlpc__din_a[31:0]", "dlpc__din_b[31:0]",
                                "dlpc__rst_active", "dlpc__init_active", "dlpc__arstz"],
}


def write_save_file(vcd):
    lines = [f'[dumpfile] "{vcd}"', "[timestart] 0"]
    for group, signals in SAVE_GROUPS.items():
        lines += [f"-{group}", "@28"]
        lines += [f"projector.{name}" for name in signals]
    path = vcd.with_suffix(".gtkw")
    path.write_text("\n".join(lines) + "\n")
    return path
