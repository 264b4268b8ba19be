"""Reading the pin traces of the fast system run (``sim/hdl/trace_recorder.v``) after the run.

A trace has a line ``<cycle> <hex value>`` for cycle 0 and every cycle on which the recorded
bus changed or was marked (DVALID high; TX_EN high); on the cycles between two lines the bus
held the earlier line's value.

:func:`replay_dlpc410` feeds a DLPC410 pin trace to the rule-checking
:class:`sim.models.dlpc410_model.Dlpc410` (``step`` on recorded cycles, ``idle`` over the gaps,
which have DVALID low) and checks on every recorded cycle that the controller outputs the Verilog
responder drove equal the model's; :func:`gmii_frames` cuts a GMII transmit trace into frames;
:func:`write_vcd` turns a window of a trace into waves.
"""

from gateware.mac import gmii as gmii_pins
from sim.harness.layout import fields
from sim.models.dlpc410_model import INPUTS, OUTPUTS

__all__ = ["read", "Mismatch", "replay_dlpc410", "rising_edges", "edges", "gmii_frames", "write_vcd"]

#: Controller outputs the responder drives and the replay compares.
COMPARED = ("init_active", "rst_active", "ecp2_finished")


class Mismatch(AssertionError):
    """The responder's outputs differ from the DLPC410 model's."""


def read(path):
    """``[(cycle, value)]`` of a trace file."""
    out = []
    with open(path) as f:
        for line in f:
            cycle, value = line.split()
            out.append((int(cycle), int(value, 16)))
    return out


def rising_edges(trace, layout, name):
    """Cycles on which field ``name`` rose (from 0 to any other level)."""
    changes = edges(trace, layout, name)
    before = [0, *(level for _, level in changes)]  # one longer: the level after the last change
    return [cycle for (cycle, level), last in zip(changes, before, strict=False) if level and not last]


def edges(trace, layout, name):
    """``(cycle, level)`` of every change of field ``name``, from level 0."""
    _, offset, mask = next(f for f in fields(layout) if f[0] == name)
    out, last = [], 0
    for cycle, value in trace:
        level = value >> offset & mask
        if level != last:
            out.append((cycle, level))
        last = level
    return out


def replay_dlpc410(model, trace, layout, *, until=None):
    """Feed ``trace`` (from :func:`read`) of pins with ``layout`` to ``model`` up to cycle
    ``until`` (default: the last record). Raises the model's RuleBreak on a broken rule and
    :class:`Mismatch` when the recorded controller outputs differ from the model's."""
    unpack = fields(layout)
    inputs = [f for f in unpack if f[0] in INPUTS]
    outputs = [f for f in unpack if f[0] in OUTPUTS and f[0] in COMPARED]

    def check(value):
        want = model.outputs()
        for name, offset, mask in outputs:
            if value >> offset & mask != want[name]:
                raise Mismatch(f"cycle {model.cycle}: the responder drove {name.upper()}="
                               f"{value >> offset & mask}, the DLPC410 model says {want[name]}")

    held = last = None
    for cycle, value in trace:
        if until is not None and cycle > until:
            break
        if cycle > model.cycle:
            # a gap: the last record's pins and the responder's outputs held throughout. The
            # model's outputs can only step once each in a gap (no pulse without DVALID), so
            # they held too if they match at its first and its last cycle.
            check(last)
            model.idle(cycle - 1 - model.cycle, held)
            check(last)
            model.idle(1, held)
        assert cycle == model.cycle, f"trace cycle {cycle} behind the model's {model.cycle}"
        check(value)
        held = {name: value >> offset & mask for name, offset, mask in inputs}
        last = value
        model.step(held)
    if until is not None and held is not None and until > model.cycle:
        model.idle(until - model.cycle, held)
    return model


def gmii_frames(trace):
    """The frames (bytes after the SFD, FCS included) on a GMII transmit trace."""
    unpack = {name: (offset, mask) for name, offset, mask in fields(gmii_pins.TxPins)}
    (d_off, d_mask), (en_off, _) = unpack["d"], unpack["en"]
    frames, current, last_cycle = [], None, None
    for cycle, value in trace:
        en = value >> en_off & 1
        if en and current is not None and cycle == last_cycle + 1:
            current.append(value >> d_off & d_mask)
        elif en:
            if current:
                frames.append(current)
            current = [value >> d_off & d_mask]
        elif current:
            frames.append(current)
            current = None
        last_cycle = cycle
    if current:
        frames.append(current)
    out = []
    for frame in frames:
        raw = bytes(frame)
        sfd = raw.find(bytes([gmii_pins.SFD_BYTE]))
        out.append(raw[sfd + 1:] if sfd >= 0 else raw)
    return out


def write_vcd(path, trace, layout, *, start, end, ns_per_cycle, scope="dlpc410"):
    """A VCD of the records of ``trace`` in cycles ``[start, end)`` (the value held at ``start``
    included), one wire per field of ``layout``; time in ns."""
    unpack = fields(layout)
    codes = {name: chr(33 + i) for i, (name, _, _) in enumerate(unpack)}
    widths = {name: mask.bit_length() for name, _, mask in unpack}
    lines = ["$timescale 1ps $end", f"$scope module {scope} $end"]
    lines += [f"$var wire {widths[n]} {codes[n]} {n} $end" for n, _, _ in unpack]
    lines += ["$upscope $end", "$enddefinitions $end"]
    last = {}
    held = next((v for c, v in reversed(trace) if c <= start), 0)
    window = [(start, held)] + [(c, v) for c, v in trace if start < c < end]
    for cycle, value in window:
        changes = []
        for name, offset, mask in unpack:
            field = value >> offset & mask
            if last.get(name) != field:
                last[name] = field
                changes.append(f"b{field:b} {codes[name]}" if widths[name] > 1 else f"{field}{codes[name]}")
        if changes:
            lines.append(f"#{round((cycle - start) * ns_per_cycle * 1000)}")
            lines += changes
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")
    return path
