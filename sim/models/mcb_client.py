"""A well-behaved MCB port client and scripted rule breaks, to hold the Verilog memory model
(``sim/hdl/mcb_model.v``) against the Python one (:mod:`sim.models.mcb_model`).

:class:`Client` is a cycle-by-cycle user of one port: ``step(outputs) -> inputs``, the same function
on both models. It follows the port's rules (write data before its command, no push while full, read
commands only when the read FIFO has room for every word in flight) and keeps the words it read.
:data:`CASES` are scripts that each break one rule, named by the Python model's
:class:`~sim.models.mcb_model.McbError` kind, for a port of a given width. :class:`LossClient` runs
a port through a calibration loss (:data:`LOSS_CASES`).
"""

import random

from sim.models.mcb_model import FIFO_DEPTH, READ, WRITE, McbError, McbModel, McbTiming

__all__ = ["Client", "traffic", "writes", "reads", "python_reads", "python_fault", "CASES", "FAULTS",
           "PERIODS_S", "WIDTHS", "LossClient", "LOSS_CASES", "LOSS_AT_NS", "LOSS_NS", "loss_plusargs",
           "python_loss", "IDLE_S", "read", "python_read_after_idle"]

#: ``mcb_model.v`` fault codes -> the Python model's error kinds.
FAULTS = {1: "before_calib", 2: "cmd_full", 3: "misaligned", 4: "out_of_range", 5: "data_missing",
          6: "wr_full", 7: "rd_empty", 8: "underrun", 9: "overflow", 10: "bad_instruction",
          11: "read_lost"}
#: The port clock periods and widths the Verilog model's default parameters stand for (the
#: store's: a 64-bit writer port, a 128-bit reader port).
PERIODS_S = (8e-9, 5e-9)
WIDTHS = (64, 128)
WORDS = 1 << 21     # mcb_model.v's default


class Client:
    """Runs ``ops``: ``("write", byte address, [(data, mask), ...])`` or ``("read", byte address,
    words)``, one command each (at most 64 port words), in order."""

    def __init__(self, ops):
        self.ops = list(ops)
        self.read = []
        self._pushed = 0          # data words of the current write already pushed
        self._in_flight = 0       # read words asked for and not yet taken

    def done(self):
        return not self.ops and self._in_flight == 0

    def step(self, out):
        inputs = {}
        if not out["calib_done"]:
            return inputs
        if not out["rd_empty"] and self._in_flight:
            self.read.append(out["rd_data"])
            self._in_flight -= 1
            inputs["rd_en"] = 1
        if not self.ops:
            return inputs
        kind, address, payload = self.ops[0]
        if kind == "write":
            if self._pushed < len(payload):
                if not out["wr_full"]:
                    data, mask = payload[self._pushed]
                    inputs.update(wr_en=1, wr_data=data, wr_mask=mask)
                    self._pushed += 1
            elif not out["cmd_full"]:
                inputs.update(cmd_en=1, cmd_instr=WRITE, cmd_bl=len(payload) - 1, cmd_byte_addr=address)
                self.ops.pop(0)
                self._pushed = 0
        elif not out["cmd_full"] and self._in_flight + payload <= FIFO_DEPTH - out["rd_count"]:
            inputs.update(cmd_en=1, cmd_instr=READ, cmd_bl=payload - 1, cmd_byte_addr=address)
            self._in_flight += payload
            self.ops.pop(0)
        return inputs


def traffic(seed=0, bursts=24, width=64, base=0):
    """Write bursts of ``width``-bit words (some bytes masked) at scattered 16-byte aligned
    addresses from ``base``, each an even number of 64-bit words long (1..64 port words), so
    that a port of either width reads them back whole."""
    rng = random.Random(seed)
    ops = []
    for i in range(bursts):
        words = rng.randint(1, 64) if width == 128 else 2 * rng.randint(1, 32)
        address = base + (i * 4096 + rng.randrange(0, 1024)) * 16
        masks = [0, 0, 0, 0x0F, 0x81] + ([0x8001, 0x00F0] if width == 128 else [])
        payload = [(rng.getrandbits(width), rng.choice(masks)) for _ in range(words)]
        ops.append(("write", address, payload))
    return ops


def writes(ops):
    return [op for op in ops if op[0] == "write"]


def reads(ops, write_width, read_width):
    """Each write's span read back in ``read_width``-bit words, in two commands where it has more
    than one word."""
    out = []
    for _kind, address, payload in writes(ops):
        words = len(payload) * write_width // read_width
        half = max(1, words // 2)
        out.append(("read", address, half))
        if words > half:
            out.append(("read", address + half * read_width // 8, words - half))
    return out


def _model(timing=None):
    return McbModel(WORDS * 8, widths=WIDTHS, timing=timing)


def _run(model, port, client, cycles=100000):
    outputs = model.ports[port].outputs
    for cycle in range(1, cycles + 1):
        outputs = model.ports[port].clock(cycle * PERIODS_S[port], **client.step(outputs))
        if client.done():
            return cycle
    raise AssertionError("the client did not finish on the Python model")


def python_reads(ops, write_port=0, read_port=1):
    """What :func:`reads` of ``ops`` returns on the Python model after the writes on
    ``write_port``, read on ``read_port``."""
    model = _model()
    _run(model, write_port, Client(writes(ops)))
    reader = Client(reads(ops, WIDTHS[write_port], WIDTHS[read_port]))
    _run(model, read_port, reader)
    return reader.read


def python_fault(script, port):
    """The error kind the Python model raises on ``script`` (per-cycle inputs) on ``port``."""
    model = _model()
    try:
        for cycle, inputs in enumerate(script, start=1):
            model.ports[port].clock(cycle * PERIODS_S[port], **inputs)
        for cycle in range(len(script) + 1, len(script) + 400):
            model.ports[port].clock(cycle * PERIODS_S[port])
    except McbError as error:
        return error.kind
    return None


#: How long the memory idles before :func:`python_read_after_idle`'s read: 256 refresh intervals.
IDLE_S = 256 * McbTiming().refresh_interval_s


def python_read_after_idle(port=1, idle_s=IDLE_S):
    """Edges of ``port`` on the Python model from a one-word read (its first edge after the
    memory idled ``idle_s`` from calibration) to the edge after which its word is in the read
    FIFO. Refreshes fall due while the memory idles and are done then: the read waits for one at
    most."""
    model = _model()
    port_model, period = model.ports[port], PERIODS_S[port]
    out, cycle = port_model.outputs, 0
    while not out["calib_done"]:
        cycle += 1
        out = port_model.clock(cycle * period)
    start = cycle * period + idle_s
    out = port_model.clock(start, **read(0))
    for edges in range(1, 10000):
        if not out["rd_empty"]:
            return edges
        out = port_model.clock(start + edges * period)
    raise AssertionError("the read after the idle time never came")


def _after_calib(*cycles):
    return [{}] * 210 + list(cycles)


def read(address, words=1):
    """The inputs of a read command of ``words`` words from byte ``address``."""
    return {"cmd_en": 1, "cmd_instr": READ, "cmd_bl": words - 1, "cmd_byte_addr": address}


#: Scripts (per-cycle inputs of one port of ``width`` bits) that break one rule each.
CASES = {
    "before_calib": lambda width: [read(0)],
    "rd_empty": lambda width: _after_calib({"rd_en": 1}),
    "misaligned": lambda width: _after_calib(read(width // 16)),          # half a port word
    "out_of_range": lambda width: _after_calib(read(WORDS * 8 - width // 8, 2)),
    "data_missing": lambda width: _after_calib({"wr_en": 1, "wr_data": 1}, {"wr_en": 1, "wr_data": 2},
                                               {"cmd_en": 1, "cmd_instr": WRITE, "cmd_bl": 2, "cmd_byte_addr": 0}),
    "wr_full": lambda width: _after_calib(*[{"wr_en": 1, "wr_data": i} for i in range(FIFO_DEPTH + 1)]),
    "cmd_full": lambda width: _after_calib(*[read(64 * width // 8 * i, 64) for i in range(8)]),
    "overflow": lambda width: _after_calib(read(0, 64), read(64 * width // 8, 64)),
}


#: The calibration loss of :class:`LossClient`'s runs: at 3 us for 1 us, well after both ports
#: calibrated and filled their FIFOs at either model's clock periods.
LOSS_AT_NS, LOSS_NS = 3000, 1000
#: What :class:`LossClient` does once calibrated again (or during the loss), and the rule each
#: breaks (None: none).
LOSS_CASES = {"read_lost": "read_lost", "rewrite": None, "before_calib": "before_calib"}
#: The outputs that show a port's FIFOs.
FIFO_OUTPUTS = ("cmd_empty", "wr_empty", "wr_count", "rd_empty", "rd_count")


def loss_plusargs():
    """The Verilog model's plusargs for :data:`LOSS_AT_NS` and :data:`LOSS_NS`."""
    return [f"+mcb_calib_lost_at_ns={LOSS_AT_NS}", f"+mcb_calib_lost_ns={LOSS_NS}"]


class LossClient:
    """A port through a calibration loss: once calibrated, writes two port words at ``address``,
    then leaves words in its FIFOs (three write words with no command, the two words read back
    not taken) and waits for the loss. It keeps its FIFO outputs of the last edge before the
    loss (``before``) and of the first calibrated one after it (``after``), then does ``case``
    (:data:`LOSS_CASES`): ``read_lost`` reads the words written before the loss, ``rewrite``
    writes them again and reads them back (into ``read``), ``before_calib`` sends a read
    command while ``calib_done`` is low. ``step(outputs) -> inputs`` on either model."""

    def __init__(self, case, width, address=0):
        assert case in LOSS_CASES, case
        self.case, self.width, self.address = case, width, address
        self.data = [(0x0123_4567_89AB_CDEF_FEDC_BA98_7654_3210 * (i + 1)) & ((1 << width) - 1) for i in range(2)]
        self.new = [d ^ ((1 << width) - 1) for d in self.data]
        self.stale = int("A5" * (width // 8), 16)     # the words left in the write FIFO
        self.before = self.after = None
        self.read = []
        self._finished = False
        self._script = self._run()
        next(self._script)

    def step(self, out):
        return self._script.send(out)

    def done(self):
        return self._finished

    def _write(self, words):
        for word in words:
            yield {"wr_en": 1, "wr_data": word}
        return (yield {"cmd_en": 1, "cmd_instr": WRITE, "cmd_bl": len(words) - 1, "cmd_byte_addr": self.address})

    def _read(self, words):
        out = yield read(self.address, words)
        got = []
        while len(got) < words:
            if out["rd_empty"]:
                out = yield {}
            else:
                got.append(out["rd_data"])
                out = yield {"rd_en": 1}
        return out, got

    def _run(self):
        out = yield
        while not out["calib_done"]:
            out = yield {}
        out = yield from self._write(self.data)
        while not (out["cmd_empty"] and out["wr_empty"]):
            out = yield {}
        # words left in the FIFOs for the loss to take
        out = yield read(self.address, 2)
        for _ in range(3):
            out = yield {"wr_en": 1, "wr_data": self.stale}
        while out["calib_done"]:
            self.before = {name: out[name] for name in FIFO_OUTPUTS}
            out = yield {}
        if self.case == "before_calib":
            out = yield read(self.address)
        while not out["calib_done"]:
            out = yield {}
        self.after = {name: out[name] for name in FIFO_OUTPUTS}
        if self.case == "read_lost":
            out, self.read = yield from self._read(2)
        elif self.case == "rewrite":
            out = yield from self._write(self.new)
            while not (out["cmd_empty"] and out["wr_empty"]):
                out = yield {}
            out, self.read = yield from self._read(2)
        self._finished = True
        while True:
            yield {}


def python_loss(case, port):
    """(error kind or None, client, model) of :class:`LossClient` ``case`` on ``port`` of the
    Python model with the loss of :data:`LOSS_AT_NS` and :data:`LOSS_NS`."""
    timing = McbTiming(calib_lost_at_s=LOSS_AT_NS * 1e-9, calib_lost_s=LOSS_NS * 1e-9)
    model = _model(timing)
    client = LossClient(case, WIDTHS[port], address=port << 16)
    outputs = model.ports[port].outputs
    try:
        for cycle in range(1, 3000):
            outputs = model.ports[port].clock(cycle * PERIODS_S[port], **client.step(outputs))
            if client.done():
                break
        for _ in range(100):            # words still on their way
            cycle += 1
            model.ports[port].clock(cycle * PERIODS_S[port])
    except McbError as error:
        return error.kind, client, model
    assert client.done(), "the client did not finish on the Python model"
    assert model.calib_losses == 1
    return None, client, model
