"""Stimulus shared by the PCS tests: the receive chain's parts joined with handles on each, a
run of per-cycle inputs through a component, the line between two PCS sides, and GMII frames
sent and received."""

from amaranth import Module
from amaranth.hdl import Elaboratable

from gateware.pcs.align import Aligner
from gateware.pcs.code_groups import Decoder, Encoder
from gateware.pcs.sync import Synchroniser
from sim.harness.amaranth_sim import simulate

__all__ = ["Chain", "run_cycles", "Line", "group_of", "PREAMBLE", "gmii_of", "frames_of", "random_frames"]

IDLE = (0, 0, 0)
PREAMBLE = [0x55] * 7 + [0xD5]


class Chain(Elaboratable):
    """Parts of the PCS in a row, each reachable by name: ``encoder`` (optional) -> ``aligner``
    (optional) -> ``decoder`` -> ``sync`` (optional)."""

    def __init__(self, *, encoder=False, aligner=False, sync=False):
        self.encoder = Encoder() if encoder else None
        self.aligner = Aligner() if aligner else None
        self.decoder = Decoder()
        self.sync = Synchroniser() if sync else None

    def elaborate(self, platform):
        m = Module()
        m.submodules.decoder = self.decoder
        if self.encoder is not None:
            m.submodules.encoder = self.encoder
            m.d.comb += self.decoder.code.eq(self.encoder.code)
        if self.aligner is not None:
            m.submodules.aligner = self.aligner
            m.d.comb += self.decoder.code.eq(self.aligner.code)
        if self.sync is not None:
            m.submodules.sync = self.sync
            m.d.comb += self.sync.received.eq(self.decoder.group)
        return m


def run_cycles(dut, steps, sample, *, name):
    """Drive each of ``steps`` (``(port, value)`` pairs) for one cycle; ``sample(ctx)`` after
    each edge, listed."""
    out = []

    async def bench(ctx):
        for step in steps:
            for port, value in step:
                ctx.set(port, value)
            await ctx.tick()
            out.append(sample(ctx))

    simulate(dut, [bench], name=name, deadline=1.0)
    return out


def group_of(ctx, group):
    """A :class:`CodeGroup` port read as ``(byte, control, code_error, disparity_error)``."""
    value = ctx.get(group)
    return int(value.data), int(value.control), int(value.code_error), int(value.disparity_error)


class Line:
    """The line between a transmitter and a receiver: 10-bit words in, the same bits out ``slip``
    bits late (zeros first); :meth:`slip` adds one more bit of delay from now on."""

    def __init__(self, slip):
        self.bits = "0" * slip

    def slip(self):
        self.bits = "1" + self.bits

    def word(self, code):
        self.bits += "".join(str(code >> i & 1) for i in range(10))
        word, self.bits = self.bits[:10], self.bits[10:]
        return sum(int(bit) << i for i, bit in enumerate(word))


def gmii_of(frames, gaps, lead=40):
    """GMII ``(tx_en, tx_er, txd)`` per cycle: ``lead`` idles, then each frame's preamble, SFD
    and bytes, each followed by its gap; a byte given as ``None`` is sent with ``tx_er``."""
    cycles = [IDLE] * lead
    for frame, gap in zip(frames, gaps, strict=True):
        cycles += [(1, 1, 0) if b is None else (1, 0, b) for b in PREAMBLE + frame] + [IDLE] * gap
    return cycles


def frames_of(pins):
    """Runs of ``rx_dv``: each as its bytes (``None`` for a byte with ``rx_er``)."""
    frames, current = [], None
    for dv, er, d in pins:
        if dv:
            current = (current or []) + [None if er else d]
        elif current is not None:
            frames.append(current)
            current = None
    return frames


def random_frames(rng, count):
    return [[rng.randrange(256) for _ in range(rng.randrange(46, 120))] for _ in range(count)]
