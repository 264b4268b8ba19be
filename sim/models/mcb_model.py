"""A model of the Spartan-6 MCB's native user ports that checks its clients.

One plain-Python :class:`McbModel` holds the memory (numpy, 64-bit words, bytes in address
order from the low bits up) and the shared DRAM timing; each :class:`McbPort` has the
fabric-side FIFOs of one port of 32, 64 or 128 bits (4 commands, 64 write words and 64 read
words of the port's width; a port word covers ``width / 8`` consecutive bytes, so a 128-bit
word holds two 64-bit memory words, the first in its low bits) and is clocked by its own
clock: :meth:`McbPort.clock` is called once per rising edge of that clock with the inputs
sampled at the edge and returns the registered outputs for the next cycle. Thin adapters
drive it from the Amaranth simulator (:func:`amaranth_process`) and from cocotb
(:class:`CocotbPort`).

Timing
------
The memory moves one byte every ``1 / (peak_bytes_per_s * efficiency)`` seconds (DDR2-800
x16: 1.6 GB/s peak, about 85-90 % sustained on sequential bursts), so a 128-bit word takes twice
the time of a 64-bit one: the DRAM, not the port, sets the bandwidth. Reads and writes of all
ports share it, commands are granted round robin. A command starts ``command_latency_s`` after it
was pushed at the earliest; read words reach the read FIFO ``read_latency_s`` after their slot on
the memory; written words leave the write FIFO one per word time. Every ``refresh_interval_s``
(7.8 us) the memory is busy for ``refresh_s`` (about 160 ns) after the command in progress.
``calib_done`` rises ``calib_delay_s`` after time 0. With ``stall_chance`` > 0, a command waits
up to ``stall_max_s`` more before it starts, at random (seeded): stalls at unpredictable times.

Calibration lost
----------------
With ``calib_lost_at_s`` set, the calibration is lost at that time and regained
``calib_lost_s`` later (once per run): ``calib_done`` is low in between on every port. At a
port's first edge at or after the loss, after that edge's inputs, the port is reset as the MCB
does: its command, write and read FIFOs, its read words in flight and its command under way are
discarded. The first port to see it also loses the memory: every 64-bit word becomes
``0xDEAD << 48 | word index`` and its bytes are marked lost until written again
(``calib_losses`` counts the losses). Until a port has seen the loss, the memory moves none of
its words (as in the Verilog model, where a port's words move only at its own edges).

Errors
------
:class:`McbError` (with a ``kind``) is raised on: traffic before ``calib_done``
(``before_calib``), a command while ``cmd_full`` (``cmd_full``), a byte address that is not a
multiple of the port's word (4, 8 or 16 bytes) or a burst outside the memory (``misaligned``,
``out_of_range``), a write command whose words are not all in the write FIFO when it is pushed
(``data_missing``), a write word
pushed while ``wr_full`` (``wr_full``), a read word taken while ``rd_empty`` (``rd_empty``), the
controller finding the write FIFO empty during a write (``underrun``, reachable only with
``check_write_data=False``, as the real MCB does not check at push time), read data arriving at
a full read FIFO (``overflow``), a read fetching a byte lost with the calibration and not written
since (``read_lost``). Traffic while ``calib_done`` is low after a loss is ``before_calib`` too.
"""

import random
from collections import deque
from dataclasses import dataclass

import numpy as np

__all__ = ["McbError", "McbTiming", "McbModel", "McbPort", "amaranth_process", "CocotbPort", "widths",
           "WRITE", "READ", "WRITE_PRECHARGE", "READ_PRECHARGE", "REFRESH"]

WRITE, READ, WRITE_PRECHARGE, READ_PRECHARGE, REFRESH = 0b000, 0b001, 0b010, 0b011, 0b100
COMMAND_DEPTH = 4
FIFO_DEPTH = 64     # port words, at every width
WIDTHS = (32, 64, 128)

INPUTS = ("cmd_en", "cmd_instr", "cmd_bl", "cmd_byte_addr", "wr_en", "wr_data", "wr_mask", "rd_en")
OUTPUTS = ("cmd_full", "cmd_empty", "wr_full", "wr_empty", "wr_count", "wr_underrun", "wr_error",
           "rd_data", "rd_full", "rd_empty", "rd_count", "rd_overflow", "rd_error", "calib_done")


class McbError(AssertionError):
    """A client broke a rule of the MCB port; ``kind`` names the rule."""

    def __init__(self, kind, message):
        super().__init__(f"MCB {kind}: {message}")
        self.kind = kind


@dataclass
class McbTiming:
    peak_bytes_per_s: float = 1.6e9     # DDR2-800 x16
    efficiency: float = 0.875           # sustained sequential efficiency
    read_latency_s: float = 60e-9
    command_latency_s: float = 10e-9
    calib_delay_s: float = 1e-6
    refresh_interval_s: float = 7.8e-6
    refresh_s: float = 160e-9
    stall_chance: float = 0.0           # chance that a command waits a random extra time first
    stall_max_s: float = 0.0            # (bank conflicts, the other port's turn, ...)
    calib_lost_at_s: float | None = None    # the calibration is lost at this time (None: never)
    calib_lost_s: float = 0.0           # and regained this much later

    def calib_lost(self, now):
        """Whether the calibration is lost at time ``now``."""
        at = self.calib_lost_at_s
        return at is not None and at <= now < at + self.calib_lost_s

    def loss_due(self, now):
        """Whether the loss has happened by time ``now``."""
        return self.calib_lost_at_s is not None and now >= self.calib_lost_at_s

    @property
    def byte_s(self):
        """Memory time of one byte."""
        return 1 / (self.peak_bytes_per_s * self.efficiency)

    @property
    def word_s(self):
        """Memory time of one 64-bit word (a port word of ``width`` bits: ``width / 64`` of it)."""
        return 8 * self.byte_s

    @property
    def sustained_bytes_per_s(self):
        """Bandwidth with refresh taken off: what all ports together can get at most."""
        return self.peak_bytes_per_s * self.efficiency * (1 - self.refresh_s / self.refresh_interval_s)


class McbModel:
    """The memory and its shared timing; ``ports`` user ports in ``self.ports``, of ``widths``
    bits (default 64 each)."""

    def __init__(self, memory_bytes=16 * 2**20, *, ports=2, widths=None, timing=None, check_write_data=True,
                 seed=0):
        widths = (64,) * ports if widths is None else tuple(widths)
        assert len(widths) == ports and all(w in WIDTHS for w in widths), widths
        self.timing = timing or McbTiming()
        self.rng = random.Random(seed)
        self.memory = np.zeros(memory_bytes // 8, dtype="<u8")
        self._bytes = self.memory.view(np.uint8)
        self.memory_bytes = memory_bytes
        self.check_write_data = check_write_data
        self.ports = [McbPort(self, i, w) for i, w in enumerate(widths)]
        self.now = 0.0
        self.busy_until = 0.0
        self.busy_s = 0.0
        self.next_refresh = self.timing.refresh_interval_s
        self.refreshes = 0
        self._next_port = 0
        #: every word written, as (byte address, port): to check nothing was written outside
        self.write_log = []
        #: per byte, lost with the calibration and not written since (None until a loss)
        self.lost = None
        self.calib_losses = 0
        #: callables that wake adapters resting on quiet ports (:meth:`lose_calibration`)
        self.wakers = []

    def calibrated(self, now):
        return now >= self.timing.calib_delay_s and not self.timing.calib_lost(now)

    def lose_calibration(self, at_s, for_s):
        """Lose the calibration at time ``at_s`` (the ports' time, ahead of every port's last
        edge), for ``for_s``: a loss decided during a run. Adapters resting on a quiet port are
        woken (``wakers``) so that every port sees ``calib_done`` fall."""
        self.timing.calib_lost_at_s = at_s
        self.timing.calib_lost_s = for_s
        for port in self.ports:
            port._quiet = False
        for wake in self.wakers:
            wake()

    def lose_memory(self):
        """The calibration is lost: every word takes a garbage value, every byte is lost."""
        self.memory[:] = np.uint64(0xDEAD << 48) | np.arange(len(self.memory), dtype="<u8")
        self.lost = np.ones(self.memory_bytes, dtype=bool)
        self.calib_losses += 1

    def _frozen(self, port):
        # lost the memory, but the port has not seen the loss yet: its work waits to be discarded
        return self.lost is not None and not port.saw_loss

    def _next_command(self):
        """(start time, port) of the next command the arbiter would grant, or (inf, None)."""
        best, chosen = float("inf"), None
        n = len(self.ports)
        for k in range(n):
            port = self.ports[(self._next_port + k) % n]
            if port.commands and not self._frozen(port):
                ready = max(self.busy_until, port.commands[0][0] + self.timing.command_latency_s)
                if ready < best:
                    best, chosen = ready, port
        return best, chosen

    def advance(self, now):
        """Run the memory up to time ``now``."""
        now = max(now, self.now)
        t = self.timing
        while True:
            start, port = self._next_command()
            due = max(self.next_refresh, self.busy_until)
            if self.next_refresh <= now and due <= start:
                self.busy_until = due + t.refresh_s
                self.busy_s += t.refresh_s
                self.next_refresh += t.refresh_interval_s
                self.refreshes += 1
                continue
            if start > now:
                break
            if t.stall_chance and self.rng.random() < t.stall_chance:
                stall = self.rng.uniform(0, t.stall_max_s)
                self.busy_until = start + stall
                self.busy_s += stall
                continue
            self._next_port = (port.index + 1) % len(self.ports)
            self._execute(port, start, *port.commands.popleft()[1:])
        for port in self.ports:
            if not self._frozen(port):
                port._deliver(now)
        self.now = now

    def read_word(self, address, size):
        """The ``size`` bytes from byte ``address``, as an int (first byte in the low bits)."""
        return int.from_bytes(self._bytes[address:address + size].tobytes(), "little")

    def write_word(self, address, size, data, mask=0):
        """Write ``data``'s ``size`` bytes at byte ``address``, but those whose ``mask`` bit is set."""
        new = data.to_bytes(size, "little")
        if not mask:
            self._bytes[address:address + size] = np.frombuffer(new, np.uint8)
            if self.lost is not None:
                self.lost[address:address + size] = False
            return
        for i in range(size):
            if not mask >> i & 1:
                self._bytes[address + i] = new[i]
                if self.lost is not None:
                    self.lost[address + i] = False

    def is_lost(self, address, size):
        """Whether any of the ``size`` bytes from byte ``address`` was lost and not written since."""
        return self.lost is not None and bool(self.lost[address:address + size].any())

    def _execute(self, port, start, instr, words, address):
        t = self.timing
        if instr == REFRESH:
            duration = t.refresh_s
        else:
            word_s = port.word_bytes * t.byte_s
            duration = words * word_s
            for i in range(words):
                at = address + i * port.word_bytes
                if instr in (WRITE, WRITE_PRECHARGE):
                    port.events.append((start + (i + 1) * word_s, "w", at))
                else:
                    port.events.append((start + t.read_latency_s + (i + 1) * word_s, "r", at))
            if instr in (WRITE, WRITE_PRECHARGE):
                port.claimed -= words
                port.draining += words
        self.busy_until = start + duration
        self.busy_s += duration


class McbPort:
    """The fabric side of one user port; see the module's documentation."""

    def __init__(self, model, index, width=64):
        self.model = model
        self.index = index
        self.width = width
        self.word_bytes = width // 8
        self._data_mask = (1 << width) - 1
        self.commands = deque()      # (push time, instr, words, byte address)
        self.write_fifo = deque()    # (data, mask)
        self.read_fifo = deque()
        self.events = deque()        # (time, "w"|"r", byte address), in time order
        self.claimed = 0             # write words owned by queued write commands
        self.draining = 0            # write words owned by started write commands
        self.underrun = self.overflow = False
        self.words_written = self.words_read = 0
        self.command_log = []        # (instr, words, byte address) of every command taken
        self.saw_loss = False        # the calibration loss reached this port
        self.outputs = self._outputs(0.0)
        self._quiet = False

    # -- the controller side

    def _deliver(self, now):
        model = self.model
        while self.events and self.events[0][0] <= now:
            _time, kind, address = self.events.popleft()
            if kind == "w":
                self.draining -= 1
                if not self.write_fifo:
                    self.underrun = True
                    raise McbError("underrun", f"port {self.index}: write FIFO empty during a write "
                                               f"command (byte address {address:#x})")
                data, mask = self.write_fifo.popleft()
                model.write_word(address, self.word_bytes, data, mask)
                model.write_log.append((address, self.index))
                self.words_written += 1
            else:
                if len(self.read_fifo) >= FIFO_DEPTH:
                    self.overflow = True
                    raise McbError("overflow", f"port {self.index}: read data arrived at a full read FIFO "
                                               f"(byte address {address:#x})")
                if model.is_lost(address, self.word_bytes):
                    raise McbError("read_lost", f"port {self.index}: read of a word lost with the "
                                                f"calibration (byte address {address:#x})")
                self.read_fifo.append(model.read_word(address, self.word_bytes))
                self.words_read += 1

    # -- the fabric side

    def clock(self, now, cmd_en=0, cmd_instr=0, cmd_bl=0, cmd_byte_addr=0, wr_en=0, wr_data=0,
              wr_mask=0, rd_en=0):
        """One rising edge of the port clock at time ``now`` (seconds), with the inputs sampled
        there. Returns the outputs for the next cycle (a dict)."""
        seen = self.outputs
        if (cmd_en or wr_en or rd_en) and not seen["calib_done"]:
            raise McbError("before_calib", f"port {self.index}: traffic while not calibrated")
        if rd_en:
            if seen["rd_empty"]:
                raise McbError("rd_empty", f"port {self.index}: rd_en while rd_empty")
            self.read_fifo.popleft()
        if cmd_en:
            self._command(now, cmd_instr, cmd_bl, cmd_byte_addr, seen)
        if wr_en:
            if seen["wr_full"]:
                raise McbError("wr_full", f"port {self.index}: wr_en while wr_full")
            self.write_fifo.append((wr_data & self._data_mask, wr_mask & ((1 << self.word_bytes) - 1)))
        if not self.saw_loss and self.model.timing.loss_due(now):
            self._lose()
        self.model.advance(now)
        self.outputs = self._outputs(now)
        # a loss still to come changes the outputs without a strobe
        self._quiet = (bool(self.outputs["calib_done"]) and self.idle()
                       and (self.saw_loss or self.model.timing.calib_lost_at_s is None))
        return self.outputs

    def _lose(self):
        """The port's first edge at or after the calibration loss: reset as the MCB does (this
        edge's inputs, already taken, go with the rest)."""
        self.saw_loss = True
        if self.model.lost is None:
            self.model.lose_memory()
        self.commands.clear()
        self.write_fifo.clear()
        self.read_fifo.clear()
        self.events.clear()
        self.claimed = self.draining = 0

    def _command(self, now, instr, bl, address, seen):
        model = self.model
        if seen["cmd_full"]:
            raise McbError("cmd_full", f"port {self.index}: cmd_en while cmd_full")
        words = bl + 1
        if instr not in (WRITE, READ, WRITE_PRECHARGE, READ_PRECHARGE, REFRESH):
            raise McbError("bad_instruction", f"port {self.index}: instruction {instr:#05b}")
        if instr != REFRESH:
            if address % self.word_bytes:
                raise McbError("misaligned", f"port {self.index}: byte address {address:#x} is not "
                                             f"a multiple of {self.word_bytes}")
            if address + words * self.word_bytes > model.memory_bytes:
                raise McbError("out_of_range", f"port {self.index}: burst at {address:#x} ends past "
                                               f"the memory")
        if instr in (WRITE, WRITE_PRECHARGE):
            # only words pushed before this cycle count: the data must be there first
            free = len(self.write_fifo) - self.claimed - self.draining
            if model.check_write_data and free < words:
                raise McbError("data_missing", f"port {self.index}: write of {words} words at "
                                               f"{address:#x} with {free} unclaimed words in the FIFO")
            self.claimed += words
        self.commands.append((now, instr, words, address))
        self.command_log.append((instr, words, address))

    def _outputs(self, now):
        wr, rd = len(self.write_fifo), len(self.read_fifo)
        return {
            "cmd_full": int(len(self.commands) >= COMMAND_DEPTH),
            "cmd_empty": int(not self.commands),
            "wr_full": int(wr >= FIFO_DEPTH),
            "wr_empty": int(wr == 0),
            "wr_count": min(wr, FIFO_DEPTH),
            "wr_underrun": int(self.underrun),
            "wr_error": int(self.underrun),
            "rd_data": self.read_fifo[0] if rd else 0,
            "rd_full": int(rd >= FIFO_DEPTH),
            "rd_empty": int(rd == 0),
            "rd_count": min(rd, FIFO_DEPTH),
            "rd_overflow": int(self.overflow),
            "rd_error": int(self.overflow),
            "calib_done": int(self.model.calibrated(now)),
        }

    def idle(self):
        """No command queued or running and no data in flight on this port."""
        return not (self.commands or self.events or self.write_fifo or self.read_fifo)

    def quiet(self):
        """Calibrated and idle when its outputs were last computed: an edge with no strobe
        (``cmd_en``, ``wr_en``, ``rd_en``) would leave every output as it is, so an adapter may
        skip :meth:`clock` for it. The memory's time moves on at the next call, on this port or
        another, with the same result. (Only this port's own commands give it work.)"""
        return self._quiet


def widths(*ports):
    """The widths of MCB port interfaces (:class:`gateware.store.mcb.PortSignature`), for
    :class:`McbModel`'s ``widths``."""
    return tuple(port.signature.width for port in ports)


def _plain(value):
    return value.value if hasattr(value, "value") else int(value)


def amaranth_process(port_model, port, *, domain, frequency):
    """An Amaranth simulator process that connects ``port_model`` to ``port`` (a component's
    :class:`gateware.store.mcb.PortSignature` member), clocked by ``domain`` at ``frequency``.
    Add it with ``simulate(..., processes=[...])``."""
    period = 1 / frequency
    inputs = [getattr(port, name) for name in INPUTS]
    outputs = {name: getattr(port, name) for name in OUTPUTS}

    async def process(ctx):
        last = {}

        def drive(values):
            for name, value in values.items():
                if last.get(name) != value:
                    ctx.set(outputs[name], value)
                    last[name] = value

        drive(port_model.outputs)
        cycle = 0
        async for _clk, rst, *values in ctx.tick(domain).sample(*inputs):
            cycle += 1
            if rst:
                continue
            drive(port_model.clock(cycle * period, *map(_plain, values)))

    return process


class CocotbPort:
    """Connects ``port_model`` to the Verilog ports ``<prefix>__<member>`` of ``dut``; start
    :meth:`run` with ``cocotb.start_soon``. ``period_ns`` is that of ``clock``.

    The model is clocked on every rising edge on which something can happen: while the port is
    quiet (:meth:`McbPort.quiet`) and no strobe was set at the last edge, the adapter waits for
    a strobe to change instead of looking at every edge.
    """

    def __init__(self, dut, prefix, clock, port_model, period_ns):
        self.inputs = {name: getattr(dut, f"{prefix}__{name}") for name in INPUTS}
        self.outputs = {name: getattr(dut, f"{prefix}__{name}") for name in OUTPUTS}
        self.clock_signal, self.model, self.period = clock, port_model, period_ns * 1e-9
        self.period_ns = period_ns
        self._last = {}
        self._drive(port_model.outputs)

    @staticmethod
    def widths(dut, *prefixes):
        """The widths of the Verilog ports ``<prefix>__*`` of ``dut``, for :class:`McbModel`'s
        ``widths``."""
        return tuple(len(getattr(dut, f"{prefix}__rd_data")) for prefix in prefixes)

    def _drive(self, values):
        # only what changed: each write is a simulator call
        for name, value in values.items():
            if self._last.get(name) != value:
                self.outputs[name].value = value
                self._last[name] = value

    def _sample(self):
        """The inputs at this edge; the data and command fields only when their strobe is set."""
        signals = self.inputs
        values = {"cmd_en": int(signals["cmd_en"].value), "wr_en": int(signals["wr_en"].value),
                  "rd_en": int(signals["rd_en"].value)}
        if values["cmd_en"]:
            for name in ("cmd_instr", "cmd_bl", "cmd_byte_addr"):
                values[name] = int(signals[name].value)
        if values["wr_en"]:
            for name in ("wr_data", "wr_mask"):
                values[name] = int(signals[name].value)
        return values

    async def run(self):
        from cocotb.triggers import Event, First, RisingEdge
        from cocotb.utils import get_sim_steps, get_sim_time
        edge = RisingEdge(self.clock_signal)
        wake = Event()
        self.model.model.wakers.append(wake.set)
        strobes = [self.inputs[name].value_change for name in ("cmd_en", "wr_en", "rd_en")]
        period = get_sim_steps(self.period_ns, "ns")
        await edge
        first, cycle = get_sim_time("step"), 1
        while True:
            inputs = self._sample()
            if not (inputs["cmd_en"] or inputs["wr_en"] or inputs["rd_en"]) and self.model.quiet():
                # a Python call per edge of an idle port is most of a long run's time: none until
                # a strobe changes, then the edges again from the next, numbered from the time
                await First(*strobes, wake.wait())
                wake.clear()
                await edge
                steps = get_sim_time("step") - first
                assert steps % period == 0, "the port's clock is not periodic"
                cycle = steps // period + 1
                continue
            self._drive(self.model.clock(cycle * self.period, **inputs))
            await edge
            cycle += 1
