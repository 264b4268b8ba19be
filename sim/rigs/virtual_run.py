"""The virtual projector: the core's generated Verilog on a TAP interface that real host software
can talk to (``make sim VIRTUAL=<seconds>``, or ``VIRTUAL=demo``).

The command makes a network namespace of its own (``dmdvp<pid>``) holding a TAP device with the
host's address (:data:`HOST_ADDRESS`) and nothing else: no route leads out of it, so no frame of the
run can leave the namespace. The simulation (:mod:`sim.tb.virtual_projector_tb`, the small geometry
with scaled RST_ACTIVE and settle times) runs inside it as the projector at :data:`PROJECTOR`; any
program started in the namespace (``ip netns exec dmdvp<pid> python -m host --address 10.0.0.2
status``) goes through the operating system's ARP, IP and UDP to it. Each frame the DMD shows is
written as a PNG under ``build/virtual/``. The namespace, and the TAP with it, is deleted when the
run ends, however it ends. It needs root or CAP_NET_ADMIN; without them it says so.

The simulator runs every model in Python per cycle (about 18,000 ``dmd`` cycles per wall
second), so the projector is some 10,000 times slower than real time: a status round trip takes
about a tenth of a second, a frame of the small geometry a few seconds. Give host commands a
timeout of several seconds (``--timeout 20``).

``VIRTUAL=demo`` (and the suite's test) runs the host CLI in the namespace against it: a ping
(ICMP through the kernel's stack, after its ARP), ``status``, ``send`` of an image, ``trigger``,
and ``status`` again; the PNG of the frame shown must equal the image sent.
"""

import json
import os
import shutil
import socket
import struct
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from sim.harness import cocotb_run
from sim.harness.paths import build_dir
from sim.models.net_model import ones_sum

__all__ = ["unavailable", "Namespace", "serve", "serve_master", "demo", "master_demo", "PROJECTOR",
           "HOST_ADDRESS"]

PROJECTOR, HOST_ADDRESS, TAP = "10.0.0.2", "10.0.0.1/24", "vp0"
#: Bounds of the demo's waits (wall seconds): the Verilator build and start, one host command.
START_S, COMMAND_S = 900, 120
CAP_NET_ADMIN = 12


def unavailable():
    """Why the virtual projector cannot run here (``None`` when it can)."""
    if os.geteuid() != 0:
        caps = next((line.split()[1] for line in Path("/proc/self/status").read_text().splitlines()
                     if line.startswith("CapEff:")), "0")
        if not int(caps, 16) >> CAP_NET_ADMIN & 1:
            return "needs root or CAP_NET_ADMIN (it makes a network namespace and a TAP device)"
    if not Path("/dev/net/tun").exists():
        return "no /dev/net/tun (TUN/TAP support) on this machine"
    if shutil.which("ip") is None:
        return "needs the ip command (iproute2)"
    return None


class Namespace:
    """A network namespace with one TAP device at :data:`HOST_ADDRESS`, deleted on exit."""

    def __init__(self):
        self.name = f"dmdvp{os.getpid()}"

    def _ip(self, *args):
        subprocess.run(["ip", "-n", self.name, *args], check=True, capture_output=True, timeout=10)

    def __enter__(self):
        subprocess.run(["ip", "netns", "add", self.name], check=True, capture_output=True, timeout=10)
        try:
            # no IPv6 chatter: the projector speaks IPv4
            self.run(["sh", "-c", "echo 1 > /proc/sys/net/ipv6/conf/default/disable_ipv6"], timeout=10)
            self._ip("link", "set", "lo", "up")
            self._ip("tuntap", "add", "dev", TAP, "mode", "tap")
            self._ip("addr", "add", HOST_ADDRESS, "dev", TAP)
            self._ip("link", "set", TAP, "up")
        except BaseException:
            self.__exit__()
            raise
        return self

    def __exit__(self, *exc):
        subprocess.run(["ip", "netns", "del", self.name], capture_output=True, timeout=10)

    def argv(self, argv):
        return ["ip", "netns", "exec", self.name, *argv]

    def run(self, argv, *, timeout=COMMAND_S, cwd=None):
        done = subprocess.run(self.argv(argv), capture_output=True, text=True, timeout=timeout, cwd=cwd)
        if done.returncode:
            raise RuntimeError(f"{' '.join(argv)} in {self.name}: exit {done.returncode}\n{done.stderr}")
        return done.stdout


def _run_files(out, seconds):
    """What every virtual device's testbench is told: its TAP, how long to run, and its files in
    ``out`` (it writes ``ready`` once up, stops when ``stop`` exists, then writes ``report``)."""
    return {"tap": TAP, "seconds": seconds, "out": str(out), "ready": str(out / "ready.json"),
            "stop": str(out / "stop"), "report": str(out / "report.json")}


def _params(out, seconds):
    from sim.rigs.system_run import PARAMS
    return {**PARAMS, **_run_files(out, seconds)}


def serve(out, seconds):
    """Run the virtual projector in this process's namespace (started by :class:`Namespace`)."""
    from sim.rigs.system_run import core_verilog
    p = _params(Path(out), seconds)
    return cocotb_run.run(core_verilog(p), toplevel="projector", module="sim.tb.virtual_projector_tb", key="test",
                          params=p, timeout_s=seconds + START_S)


#: The virtual sync master's build: four boards, every time in its 125 MHz cycles, disarmed.
MASTER_BOARDS, MASTER_CONFIG = 4, {"mode": 0, "armed": 0, "period": 125_000, "min_period": 12_500, "width": 125}


def serve_master(out, seconds):
    """Run the virtual sync master in this process's namespace, at :data:`PROJECTOR`'s address."""
    from gateware.top.sync_master import SyncMasterCore
    from sim.tb.gmii_host import address_value
    p = {**_run_files(Path(out), seconds), "mac": "02:44:4d:00:00:f0", "ip": PROJECTOR, "port": 5000,
         "boards": MASTER_BOARDS}
    core = SyncMasterCore(MASTER_BOARDS, config=MASTER_CONFIG, mac=address_value(p["mac"]),
                          ip=address_value(PROJECTOR), port=p["port"], mdio_cycles=(20, 20))
    return cocotb_run.run(core, toplevel="sync_master_core", module="sim.tb.virtual_master_tb", key="virtual",
                          params=p, timeout_s=seconds + START_S)


def _start(ns, out, seconds, device="serve"):
    for name in ("ready.json", "stop", "report.json"):
        (out / name).unlink(missing_ok=True)
    for png in out.glob("frame*.png"):
        png.unlink()
    log = open(out / "simulation.log", "w")    # noqa: SIM115 (the process outlives this call)
    server = subprocess.Popen(ns.argv([sys.executable, "-m", "sim.rigs.virtual_run", device, str(out), str(seconds)]),
                              stdout=log, stderr=subprocess.STDOUT)
    deadline = time.monotonic() + START_S
    while not (out / "ready.json").exists():
        if server.poll() is not None or time.monotonic() > deadline:
            server.kill()
            raise RuntimeError(f"the virtual projector did not start: see {out / 'simulation.log'}")
        time.sleep(0.5)
    return server


def _stop(server, out):
    (out / "stop").touch()
    try:
        server.wait(timeout=COMMAND_S)
    except subprocess.TimeoutExpired:
        server.kill()
        server.wait()
    report = out / "report.json"
    return json.loads(report.read_text()) if report.exists() else None


def main(seconds, log=print):
    """``make sim VIRTUAL=<seconds>``: serve for that long (Ctrl-C ends it sooner)."""
    reason = unavailable()
    if reason:
        log(f"virtual projector: {reason}")
        return 2
    out = build_dir("virtual", "serve")
    with Namespace() as ns:
        log(f"virtual projector: building and starting the core in network namespace {ns.name} ...")
        server = _start(ns, out, seconds)
        log(f"virtual projector at {PROJECTOR} in namespace {ns.name} for {seconds:g} s; host software runs there:\n"
            f"  ip netns exec {ns.name} {sys.executable} -m host --address {PROJECTOR} --timeout 20 status\n"
            f"frames shown are written to {out}/frameNNNN.png")
        try:
            server.wait(timeout=seconds + COMMAND_S)
        except (KeyboardInterrupt, subprocess.TimeoutExpired):
            pass
        finally:
            report = _stop(server, out)
    log(f"virtual projector stopped: {report}")
    return 0


def ping(address, timeout=10.0):
    """One ICMP echo through the kernel (it ARPs first); returns the round trip in seconds."""
    sock = socket.socket(socket.AF_INET, socket.SOCK_RAW, socket.IPPROTO_ICMP)
    sock.settimeout(timeout)
    ident, payload = os.getpid() & 0xFFFF, b"dmd projector ping"
    checksum = ~ones_sum(struct.pack("!BBHHH", 8, 0, 0, ident, 1) + payload) & 0xFFFF
    t0 = time.monotonic()
    sock.sendto(struct.pack("!BBHHH", 8, 0, checksum, ident, 1) + payload, (address, 0))
    while True:
        data, (source, _) = sock.recvfrom(2048)
        icmp = data[(data[0] & 0xF) * 4:]
        if source == address and icmp[0] == 0 and struct.unpack("!H", icmp[4:6])[0] == ident:
            assert icmp[8:] == payload, "echo reply with other data"
            return time.monotonic() - t0


def demo(seconds=600, log=print, python=sys.executable, cwd=None):
    """``make sim VIRTUAL=demo``: the host CLI in the namespace pings, reads the status, sends an
    image, triggers it and reads the status again; returns the report (the frame shown against
    the image sent, the status before and after, the round trips). ``python``, ``cwd``: the
    interpreter that runs the host CLI and its working directory (an installed host package in
    another environment: not this checkout's)."""
    reason = unavailable()
    if reason:
        raise RuntimeError(f"virtual projector: {reason}")
    from sim.rigs.scene import default_scene
    from sim.rigs.system_run import PARAMS
    from spec.facts import DMDS
    dmd = DMDS[PARAMS["dmd"]]
    out = build_dir("virtual", "demo")
    image = default_scene(1, dmd.rows, dmd.columns)[0]
    np.save(out / "image.npy", image)
    host = [python, "-m", "host", "--address", PROJECTOR, "--timeout", "20"]
    steps = {}
    with Namespace() as ns:
        log(f"virtual projector: building and starting the core in network namespace {ns.name} ...")
        server = _start(ns, out, seconds)
        try:
            t0 = time.monotonic()
            pinger = f"from sim.rigs.virtual_run import ping; print(ping({PROJECTOR!r}))"
            steps["ping_s"] = float(ns.run([sys.executable, "-c", pinger]))
            log(f"ping {PROJECTOR}: reply after {steps['ping_s']:.2f} s wall")
            steps["status_before"] = ns.run(host + ["status"], cwd=cwd)
            steps["send"] = ns.run(host + ["send", "--depth", "8", str(out / "image.npy")], cwd=cwd)
            log(steps["send"].strip())
            ns.run(host + ["trigger"], cwd=cwd)
            deadline = time.monotonic() + COMMAND_S
            while not (out / "frame0000.png").exists() and time.monotonic() < deadline:
                time.sleep(0.5)
            time.sleep(1.0)
            steps["status_after"] = ns.run(host + ["status"], cwd=cwd)
            steps["wall_s"] = time.monotonic() - t0
        finally:
            report = _stop(server, out)
    if report is None:
        raise RuntimeError(f"the virtual projector wrote no report: see {out / 'simulation.log'}")
    report.update(steps)
    report["image"] = str(out / "image.npy")
    if report["shown"]:
        from PIL import Image
        shown = np.asarray(Image.open(report["shown"][0]["png"]))
        report["max_error_lsb"] = int(np.abs(shown.astype(int) - image.astype(int)).max())
        log(f"frame shown: {report['shown'][0]['png']}, max error {report['max_error_lsb']} LSB against the image sent")
    return report


def master_demo(seconds=300, log=print):
    """The host CLI's ``master`` command in the namespace against the virtual sync master: its
    status, a configuration (software triggers, armed, a shortest frame period and a pulse width)
    with a trigger, its status again; returns the report (the pulses read on the pins, their
    lengths, the CLI's output)."""
    reason = unavailable()
    if reason:
        raise RuntimeError(f"virtual sync master: {reason}")
    out = build_dir("virtual", "master")
    host = [sys.executable, "-m", "host", "--timeout", "20", "master", PROJECTOR]
    steps = {}
    with Namespace() as ns:
        log(f"virtual sync master: building and starting its core in network namespace {ns.name} ...")
        server = _start(ns, out, seconds, "serve-master")
        try:
            steps["status_before"] = ns.run(host + ["--status"])
            steps["configured"] = ns.run(host + ["--mode", "software", "--arm", "--min-period", "1e-4",
                                                 "--width", "2e-7", "--trigger"])
            steps["status_after"] = ns.run(host + ["--status"])
        finally:
            report = _stop(server, out)
    if report is None:
        raise RuntimeError(f"the virtual sync master wrote no report: see {out / 'simulation.log'}")
    return {**report, **steps}


if __name__ == "__main__":
    if sys.argv[1] == "serve":
        serve(Path(sys.argv[2]), float(sys.argv[3]))
    elif sys.argv[1] == "serve-master":
        serve_master(Path(sys.argv[2]), float(sys.argv[3]))
