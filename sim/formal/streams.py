"""The stream rules as formal properties, on every stream port of a component.

The rules of :mod:`amaranth.lib.stream`: once ``valid`` is high it stays high, with the same
payload, until the cycle ``ready`` takes it; and ``valid`` does not wait for ``ready``.
:func:`stream_rules` assumes the first rule of the component's input streams (its producers
keep it) and asserts it of its output streams (whatever the consumers' ``ready`` do, which
stay free). :func:`ready_paths` proves the second structurally: no output stream's ``valid``
has a combinational path from any ``ready`` the consumers drive.
"""

import itertools
import re

from amaranth import Signal
from amaranth.back import rtlil
from amaranth.hdl import Assert, Assume
from amaranth.lib import stream, wiring

from .tools import yosys

__all__ = ["stream_ports", "stream_rules", "ready_paths"]


def stream_ports(dut):
    """``(path, produced, interface)`` for each stream port of ``dut`` at any depth (arrays and
    nested signatures included); ``produced``: the component drives ``valid`` and ``payload``."""
    def walk(signature, obj, path, flipped):
        for name, member in signature.members.items():
            if not member.is_signature:
                continue
            inward = (member.flow == wiring.In) != flipped
            for index in itertools.product(*map(range, member.dimensions)):
                item = getattr(obj, name)
                for i in index:
                    item = item[i]
                where = (*path, name, *index)
                if isinstance(member.signature, stream.Signature):
                    yield where, not inward, item
                else:
                    yield from walk(member.signature, item, where, inward)
    yield from walk(dut.signature, dut, (), False)


def _held(m, domain, port, name, statement, reset=None):
    """``statement`` (Assert or Assume): a payload offered and not taken is offered again,
    unchanged; unless ``reset`` (a synchronous reset of the producer) is high now or was on the
    cycle before."""
    ready = port.ready
    if not isinstance(ready, Signal):
        return                           # always ready: every offer is a transfer
    payload = port.payload.as_value() if hasattr(port.payload, "as_value") else port.payload
    waiting = Signal(name=f"{name}__waiting")
    offered = port.valid & ~ready
    if reset is not None:
        was_reset = Signal(name=f"{name}__was_reset")
        m.d[domain] += was_reset.eq(reset)
        m.d[domain] += waiting.eq(offered & ~reset)
        waiting = waiting & ~reset & ~was_reset
    else:
        m.d[domain] += waiting.eq(offered)
    with m.If(waiting):
        m.d.comb += statement(port.valid, f"{name}: valid fell before the transfer")
    if len(payload):
        before = Signal(len(payload), name=f"{name}__before")
        m.d[domain] += before.eq(payload)
        with m.If(waiting):
            m.d.comb += statement(payload == before, f"{name}: payload changed before the transfer")


def stream_rules(exclude=(), parts=(), resets=()):
    """A property function ``f(m, top)`` for :class:`sim.formal.harness.FormalTop`: the stream
    rules on every stream port of ``top.dut`` but those named in ``exclude``, each in the port's
    domain (``top.port_domains``). ``parts``: ``(name, component, {port: domain})`` of parts
    inside ``top.dut``, whose streams between each other are asserted too (a part's streams
    from the boundary are the top's own, assumed there and so holding here). ``resets``: names
    of one-bit inputs of ``top.dut`` that reset it synchronously (the writer's ``discard``): an
    output stream may be withdrawn only while one is high (or the cycle after)."""
    def prop(m, top):
        reset = None
        for name in resets:
            signal = getattr(top.dut, name)
            reset = signal if reset is None else reset | signal
        for path, produced, port in stream_ports(top.dut):
            if path[0] in exclude:
                continue
            name = "__".join(map(str, path))
            _held(m, top.domain_of(path), port, name, Assert if produced else Assume,
                  reset if produced else None)
        for part_name, part, domains in parts:
            for path, _produced, port in stream_ports(part):
                name = "__".join([part_name, *map(str, path)])
                _held(m, domains.get(path[0], "sync"), port, name, Assert)
    return prop


def _port_name(path, leaf):
    return "__".join([*map(str, path), leaf])


def ready_paths(dut, folder):
    """Output streams of ``dut`` whose ``valid`` has a combinational path from a consumer's
    ``ready``: ``{valid port: [ready ports]}``, empty when the rule holds. Yosys follows every
    combinational cell from each ``ready`` input of the flattened component (in ``folder``)."""
    ports = list(stream_ports(dut))
    readies = [_port_name(path, "ready") for path, produced, port in ports
               if produced and isinstance(port.ready, Signal)]
    valids = [_port_name(path, "valid") for path, produced, port in ports
              if produced and isinstance(port.valid, Signal)]
    if not readies or not valids:
        return {}
    # (an always-ready stream's ``ready`` is a constant, which cannot be a port)
    signals = [value for _path, _member, value in dut.signature.flatten(dut) if isinstance(value, Signal)]
    text = rtlil.convert(dut, name="dut", ports=signals, emit_src=False)
    script = ["read_rtlil dut.il", "hierarchy -top dut", "proc", "flatten", "opt_clean"]
    for valid in valids:
        for ready in readies:
            script.append(f"log PATH? {valid} {ready}")
            script.append(f"select -count w:{ready} %coe* w:{valid} %i")
    log = yosys(folder, script, {"dut.il": text})
    found = {}
    pending = None
    for line in log.splitlines():
        if match := re.search(r"PATH\? (\S+) (\S+)", line):
            pending = match.groups()
        elif pending and (match := re.search(r"(\d+) objects", line)):
            if int(match.group(1)):
                found.setdefault(pending[0], []).append(pending[1])
            pending = None
    return found
