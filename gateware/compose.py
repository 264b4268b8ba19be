"""Wrappers built from their children: take a child's ports as one's own, and wire them through.

A wrapper that exposes some of a child's ports declares them with :func:`members` (so the child's
signature stays the one definition) and connects them with :func:`forward`.
"""

from amaranth.lib import wiring
from amaranth.lib.wiring import Out

__all__ = ["members", "forward"]


def members(component, names=None, *, exclude=()):
    """``{name: member}`` of ``component``'s signature: those in ``names`` (default: all), less
    those in ``exclude``."""
    items = component.signature.members.items()
    return {name: member for name, member in items
            if (names is None or name in names) and name not in exclude}


def forward(m, outer, inner, names=None):
    """Wire each port ``names`` (default: every port the two share) of ``outer`` to the port of
    the same name and flow of ``inner``: interfaces with :func:`amaranth.lib.wiring.connect`,
    plain signals by assignment in the direction of their flow."""
    shared = [name for name in outer.signature.members if name in inner.signature.members]
    for name in shared if names is None else names:
        member = outer.signature.members[name]
        ours, theirs = getattr(outer, name), getattr(inner, name)
        if member.is_signature:
            if member.flow == Out:
                wiring.connect(m, theirs, wiring.flipped(ours))
            else:
                wiring.connect(m, wiring.flipped(ours), theirs)
        elif member.flow == Out:
            m.d.comb += ours.eq(theirs)
        else:
            m.d.comb += theirs.eq(ours)
