"""The stream rules as formal properties, on every stream port of a component.

The rules of :mod:`amaranth.lib.stream`: once ``valid`` is high it stays high, with the same
payload, until the cycle ``ready`` takes it; and ``valid`` does not wait for ``ready``.
:func:`stream_rules` assumes the first rule of the component's input streams (its producers
keep it) and asserts it of its output streams (whatever the consumers' ``ready`` do, which
stay free), with covers of a transfer, and of one after backpressure, on each output stream: the
check must reach the state its rule is about. :func:`ready_paths` proves the second
structurally: no output stream's ``valid`` has a combinational path from any ``ready`` the
consumers drive.
"""

import itertools
import re

from amaranth import Signal
from amaranth.back import rtlil
from amaranth.hdl import Assert, Assume, Cover
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


def _held(m, domain, port, name, statement, reset=None, cover=None):
    """``statement`` (Assert or Assume): a payload offered and not taken is offered again,
    unchanged; unless ``reset`` (a synchronous reset of the producer) is high now or was on the
    cycle before. ``cover``: ``"transfer"`` covers a transfer; ``"backpressure"`` also a
    transfer after backpressure, the event the rule is about (for a stream whose consumer's
    ``ready`` is free: an inner consumer may never hold one back)."""
    ready = port.ready
    if cover:
        m.d.comb += Cover(port.valid & ready, f"{name}: a transfer")
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
    if cover == "backpressure":
        m.d.comb += Cover(waiting & port.valid & ready, f"{name}: a transfer after backpressure")
    with m.If(waiting):
        m.d.comb += statement(port.valid, f"{name}: valid fell before the transfer")
    if len(payload):
        before = Signal(len(payload), name=f"{name}__before")
        m.d[domain] += before.eq(payload)
        with m.If(waiting):
            m.d.comb += statement(payload == before, f"{name}: payload changed before the transfer")


def stream_rules(exclude=(), parts=(), resets=(), uncovered=()):
    """A property function ``f(m, top)`` for :class:`sim.formal.harness.FormalTop`: the stream
    rules on every stream port of ``top.dut`` but those named in ``exclude``, each in the port's
    domain (``top.port_domains``). ``parts``: ``(name, component, {port: domain})`` of parts
    inside ``top.dut``, whose output streams are asserted too (a part's streams from the
    boundary are the top's own, assumed there and so holding here). ``resets``: names
    of one-bit inputs of ``top.dut`` (or one-bit values) that reset it synchronously (the
    writer's ``discard``): an
    output stream may be withdrawn only while one is high (or the cycle after); a part's entry
    may add a fourth item, a signal that resets that part's output streams so. Each output
    stream (of the top or of a part) has a cover of a transfer after backpressure."""
    def prop(m, top):
        reset = None
        for name in resets:
            signal = getattr(top.dut, name) if isinstance(name, str) else name
            reset = signal if reset is None else reset | signal
        for path, produced, port in stream_ports(top.dut):
            if path[0] in exclude:
                continue
            name = "__".join(map(str, path))
            _held(m, top.domain_of(path), port, name, Assert if produced else Assume,
                  reset if produced else None,
                  cover="backpressure" if produced and path[0] not in uncovered else None)
        for part_name, part, domains, *part_reset in parts:
            for path, produced, port in stream_ports(part):
                if not produced:
                    continue             # (the same wires as the producing part's stream)
                name = "__".join([part_name, *map(str, path)])
                _held(m, domains.get(path[0], "sync"), port, name, Assert, part_reset[0] if part_reset else None,
                      cover=None if part_name in uncovered else "transfer")
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
