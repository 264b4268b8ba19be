"""cocotb: the Verilog MCB model (``sim/hdl/mcb_model.v``) against the Python one.

The same client (:class:`sim.models.mcb_client.Client`) runs on both, with the model's default
ports (64 bits on port 0, 128 on port 1): the words it reads back must agree. Scripted rule
breaks, one per port and run (the Verilog fault code is sticky), must give the rule the Python
model names; so must a calibration loss (:class:`sim.models.mcb_client.LossClient`), with the
same FIFOs before and after it and the same words read back.

Run by ``tests/test_mcb_verilog_model.py``.
"""

import cocotb
from amaranth import Shape
from amaranth.lib import wiring
from cocotb.triggers import Timer

from gateware.store import mcb
from sim.harness.cocotb_run import params
from sim.models import mcb_client


def _widths(flow):
    return {name: Shape.cast(member.shape).width for name, member in mcb.PortSignature(128).members.items()
            if member.flow == flow}


#: The members' slots in the model's vectors (those of the widest port), driven by the user (the
#: model's inputs) and by the model; a narrower port uses the low bits of its data and mask slots.
WIDTHS, OUT_WIDTHS = _widths(wiring.Out), _widths(wiring.In)


class Ports:
    """Reads and writes one port's slices of the model's vectors. Both ports' inputs are kept
    here, as the vectors are shared."""

    def __init__(self, dut):
        self.dut = dut
        self.inputs = [dict.fromkeys(WIDTHS, 0), dict.fromkeys(WIDTHS, 0)]

    def drive(self, port, values):
        self.inputs[port] = {**dict.fromkeys(WIDTHS, 0), **values}
        for name, width in WIDTHS.items():
            getattr(self.dut, name).value = sum(self.inputs[p][name] << (width * p) for p in range(2))

    def sample(self, port):
        out = {}
        for name, width in OUT_WIDTHS.items():
            out[name] = int(getattr(self.dut, name).value) >> (width * port) & ((1 << width) - 1)
        return out

    def fault(self, port):
        return mcb_client.FAULTS.get(int(self.dut.fault.value) >> (4 * port) & 0xF)


async def start(dut):
    ports = Ports(dut)
    for port in range(2):
        ports.drive(port, {})
    dut.clk.value = 0
    return ports


async def run_ports(dut, ports, steps, cycles, until=None):
    """Both ports on one clock (timing is not compared): each cycle, the outputs after the edge
    go to that port's ``step``, which returns the inputs for the next edge (None: idle)."""
    for _ in range(cycles):
        if until is not None and until():
            return
        await Timer(2, "ns")
        for port, step in enumerate(steps):
            ports.drive(port, (step(ports.sample(port)) if step else None) or {})
        await Timer(1, "ns")
        dut.clk.value = 3
        await Timer(2, "ns")
        dut.clk.value = 0


@cocotb.test()
async def client_traffic_agrees(dut):
    """Writes (some masked) on one port, then reads on the other: same words as the Python
    model, 64-bit words written and read as 128-bit ones, then 128-bit ones as 64-bit ones."""
    ports = await start(dut)
    for write_port, base in ((0, 0), (1, 2**23)):
        read_port = 1 - write_port
        ops = mcb_client.traffic(seed=1 + write_port, width=mcb_client.WIDTHS[write_port], base=base)
        writer = mcb_client.Client(mcb_client.writes(ops))
        reader = mcb_client.Client(mcb_client.reads(ops, mcb_client.WIDTHS[write_port], mcb_client.WIDTHS[read_port]))
        steps = [None, None]
        steps[write_port] = writer.step
        await run_ports(dut, ports, steps, 20000, until=writer.done)
        assert writer.done(), f"the writes on port {write_port} did not finish"
        steps = [None, None]
        steps[read_port] = reader.step
        await run_ports(dut, ports, steps, 20000, until=reader.done)
        assert reader.done(), f"the reads on port {read_port} did not finish"
        want = mcb_client.python_reads(ops, write_port, read_port)
        assert len(reader.read) == len(want), f"{len(reader.read)} words read, the Python model {len(want)}"
        assert reader.read == want, f"{sum(a != b for a, b in zip(reader.read, want, strict=True))} words differ"
    assert ports.fault(0) is None and ports.fault(1) is None


@cocotb.test()
async def scripted_rule_breaks(dut):
    """One scripted sequence per port; each port's fault names the Python model's rule."""
    p = params()
    ports = await start(dut)
    widths = mcb_client.WIDTHS
    scripts = [iter(mcb_client.CASES[name](widths[port])) for port, name in enumerate(p["case"])]
    await run_ports(dut, ports, [lambda _out, s=s: next(s, None) for s in scripts], 1000)
    for port, name in enumerate(p["case"]):
        want = mcb_client.python_fault(mcb_client.CASES[name](widths[port]), port)
        assert want == name, f"the Python model says {want} for case {name}"
        assert ports.fault(port) == want, f"port {port}: Verilog says {ports.fault(port)}, Python {want}"


@cocotb.test()
async def calibration_loss(dut):
    """A loss case per port (plusargs: :func:`sim.models.mcb_client.loss_plusargs`), each
    against the Python model's run of it: same rule broken, FIFOs, words read back (the lost
    words' garbage too)."""
    p = params()
    ports = await start(dut)
    widths = mcb_client.WIDTHS
    clients = [mcb_client.LossClient(name, widths[port], address=port << 16) for port, name in enumerate(p["case"])]
    await run_ports(dut, ports, [c.step for c in clients], 2000)
    assert int(dut.calib_losses.value) == 1
    for port, (name, client) in enumerate(zip(p["case"], clients, strict=True)):
        want, reference, model = mcb_client.python_loss(name, port)
        assert want == mcb_client.LOSS_CASES[name], f"the Python model says {want} for case {name}"
        assert ports.fault(port) == want, f"port {port}: Verilog says {ports.fault(port)}, Python {want}"
        assert client.before == reference.before, \
            f"port {port}: before the loss {client.before}, Python {reference.before}"
        if name != "before_calib":       # the Python run stops at the rule break, the Verilog one goes on
            assert client.after == reference.after, \
                f"port {port}: after the loss {client.after}, Python {reference.after}"
        if name == "rewrite":
            assert client.done() and client.read == reference.read == client.new, \
                f"port {port}: read back {client.read}, Python {reference.read}"
        if name == "read_lost":
            size = widths[port] // 8
            garbage = [model.read_word(client.address + i * size, size) for i in range(2)]
            assert client.read == garbage, f"port {port}: read {client.read}, the Python model holds {garbage}"


@cocotb.test()
async def read_after_idle(dut):
    """A read on port 1 after the memory idled for hundreds of refresh intervals: its word comes
    after as many edges as on the Python model (the refreshes fell due while the memory idled and
    were done then; they do not pile up on the next command)."""
    ports = await start(dut)
    await run_ports(dut, ports, [None, None], 1000, until=lambda: ports.sample(1)["calib_done"])
    await Timer(round(mcb_client.IDLE_S * 1e9), "ns")        # no edge: the memory idles
    seen = {"edges": 0, "word": False}

    def step(out):
        if seen["edges"]:
            seen["word"] = seen["word"] or not out["rd_empty"]
        seen["edges"] += not seen["word"]
        return mcb_client.read(0) if seen["edges"] == 1 else None

    await run_ports(dut, ports, [None, step], 20000, until=lambda: seen["word"])
    want = mcb_client.python_read_after_idle()
    assert seen["word"], "the read after the idle time never came"
    assert seen["edges"] == want, f"{seen['edges']} edges to the word, the Python model {want}"
    assert ports.fault(1) is None
