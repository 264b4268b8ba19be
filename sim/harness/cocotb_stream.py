"""cocotb drivers for Amaranth :mod:`lib.stream` ports in generated Verilog.

A stream port ``name`` of a component becomes ``name__valid``, ``name__ready`` and
``name__payload`` in the Verilog. :class:`StreamSource` and :class:`StreamSink` drive them with
the stream rules and speak the payload's layout by field names.
"""

import random

from cocotb.triggers import RisingEdge

from .layout import pack, unpack

__all__ = ["StreamSource", "StreamSink"]


class StreamSource:
    """Offers payloads on ``dut.<name>__*``; ``idle`` is the chance of an idle cycle before each.
    ``stalls`` counts the cycles a payload was offered and not taken."""

    def __init__(self, dut, name, layout, clock, *, idle=0.0, seed=0):
        self.valid = getattr(dut, f"{name}__valid")
        self.ready = getattr(dut, f"{name}__ready")
        self.payload = getattr(dut, f"{name}__payload")
        self.layout, self.clock = layout, clock
        self.idle, self.rng = idle, random.Random(seed)
        self.stalls = 0
        self.valid.value = 0

    async def send(self, items):
        for item in items:
            while self.idle and self.rng.random() < self.idle:
                self.valid.value = 0
                await RisingEdge(self.clock)
            self.payload.value = pack(self.layout, item)
            self.valid.value = 1
            while True:
                await RisingEdge(self.clock)
                if self.ready.value:
                    break
                self.stalls += 1
        self.valid.value = 0


class StreamSink:
    """Accepts payloads from ``dut.<name>__*``; ``stall`` is the chance of holding ready low."""

    def __init__(self, dut, name, layout, clock, *, stall=0.0, seed=1):
        self.valid = getattr(dut, f"{name}__valid")
        self.ready = getattr(dut, f"{name}__ready")
        self.payload = getattr(dut, f"{name}__payload")
        self.layout, self.clock = layout, clock
        self.stall, self.rng = stall, random.Random(seed)
        self.ready.value = 0

    async def receive(self, count):
        out, driven = [], None
        while len(out) < count:
            ready = not (self.stall and self.rng.random() < self.stall)
            if ready != driven:        # each write is a simulator call
                self.ready.value = driven = ready
            await RisingEdge(self.clock)
            # values read just after the edge are those the edge sampled (as cocotbext-axi reads them)
            if ready and self.valid.value:
                out.append(unpack(self.layout, self.payload.value.to_unsigned()))
        self.ready.value = 0
        return out

