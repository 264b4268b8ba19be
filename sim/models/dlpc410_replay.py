"""A tiny Amaranth component that replays driver-built DLPC410 cycles from a ROM, and the
sequences the adapter tests replay.

It proves the two adapters of :mod:`sim.models.dlpc410_model` (Amaranth simulator and cocotb on the
generated Verilog) see exactly what the pure-Python model sees when fed the same cycles: the
replay is blind (it ignores the controller's outputs), so the same legal sequence gives the same
command log and mirrors, and the illegal one the same named rule break, through either adapter.
"""

from amaranth import Array, Module, Signal
from amaranth.hdl import Value
from amaranth.lib import data, wiring
from amaranth.lib.memory import Memory
from amaranth.lib.wiring import In, Out

from gateware.dlpc410 import interface
from spec.facts import TEST_DMD

from .dlpc410_driver import Driver, expand

__all__ = ["Replay", "MODEL_PARAMS", "NAMES", "sequences", "replay", "entry_layout"]

#: Short timing for the replayed sequences (the ROM holds every cycle).
MODEL_PARAMS = {"rst_active_cycles": 12, "settle_cycles": 20, "init_cycles": 16}

#: The sequences :func:`replay` holds, in ``select`` order.
NAMES = ("legal", "illegal")

_CONTROLS = {"dvalid": 1, "rowmd": 2, "rowad": 11, "blkmd": 2, "blkad": 4, "rst2blkz": 1,
             "comp_data": 1, "ns_flip": 1, "arstz": 1}


def entry_layout(buses):
    """One ROM entry: every pin the replay drives, for one cycle."""
    return data.StructLayout({**_CONTROLS, **{f"din_{b}": 32 for b in "abcd"[:buses]}})


def sequences(dmd=TEST_DMD):
    """``{"legal": items, "illegal": items}`` for ``dmd`` with :data:`MODEL_PARAMS` timing.

    legal: start-up, a full plane, a global pulse, a clear, part of a second plane, a single and a
    dual pulse. illegal: start-up, a plane, a global pulse, then a pulse while RST_ACTIVE is high.
    """
    r, s = MODEL_PARAMS["rst_active_cycles"], MODEL_PARAMS["settle_cycles"]
    a = [[(row * 7 + col * 3) % 5 == 0 for col in range(dmd.columns)] for row in range(dmd.rows)]
    b = [[(row + col) % 3 == 0 for col in range(dmd.columns)] for row in range(dmd.rows)]
    rpb = dmd.rows_per_block
    out = {}
    for name in NAMES:
        d = Driver(dmd)
        d.start(MODEL_PARAMS["init_cycles"])
        d.load(a)
        p = d.pulse("global")
        if name == "illegal":
            d.pulse("single", 0)
        else:
            d.wait_until(p + r + 1 + s)
            d.clear(2)
            d.load(b, rows=range(rpb, 2 * rpb))
            p = d.pulse("single", 1)
            d.wait_until(p + r + 1)
            d.pulse("dual", 1)
        d.idle(4)
        out[name] = list(expand(d.items))
    return out


def replay(dmd=TEST_DMD):
    """A :class:`Replay` of every sequence of :func:`sequences`, ``select`` = index in NAMES."""
    seqs = sequences(dmd)
    return Replay(dmd, [seqs[name] for name in NAMES])


class Replay(wiring.Component):
    """Drives the DLPC410 pins from a ROM of cycles, one entry per cycle, then holds the last.

    Parameters
    ----------
    dmd : DmdType
    sequences : list of lists of dicts
        Per-cycle signal dicts (:meth:`sim.models.dlpc410_model.Dlpc410.step`'s form).

    Ports
    -----
    dlpc : Out(dlpc410.interface.Signature)
        The replayed pins; the controller's outputs are ignored.
    select : In(range(len(sequences)))
        Which sequence plays (set it during reset).
    done : Out(1)
        The last entry of the sequence is being driven.
    """

    def __init__(self, dmd, sequences):
        self._dmd = dmd
        self._layout = entry_layout(dmd.buses)
        self._lengths = [len(seq) for seq in sequences]
        self._offsets = [sum(self._lengths[:i]) for i in range(len(sequences))]
        self._init = [{name: int(cycle.get(name, _default(name))) for name, _ in self._layout}
                      for seq in sequences for cycle in seq]
        super().__init__({
            "dlpc": Out(interface.Signature(dmd.buses)),
            "select": In(range(max(2, len(sequences)))),
            "done": Out(1),
        })

    def elaborate(self, platform):
        m = Module()
        m.submodules.rom = rom = Memory(shape=self._layout, depth=len(self._init), init=self._init)
        read = rom.read_port(domain="comb")
        index = Signal(range(max(self._lengths) + 1))
        last = Array(self._lengths)[self.select] - 1
        m.d.comb += [
            read.addr.eq(Array(self._offsets)[self.select] + index),
            self.done.eq(index == last),
        ]
        with m.If(index != last):
            m.d.sync += index.eq(index + 1)
        for name, _ in self._layout:
            m.d.comb += Value.cast(getattr(self.dlpc, name)).eq(getattr(read.data, name))
        return m


def _default(name):
    return {"rst2blkz": 1}.get(name, 0)
