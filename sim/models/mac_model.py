"""Reference model of the GMII MAC, and Ethernet frames built by scapy as an independent oracle.

Frames here are ``bytes`` from the destination MAC to the end of the payload; :func:`with_fcs`
appends the FCS computed by :func:`zlib.crc32`. On the wire a frame is a list of *symbols*
``(d, dv, er)``, one per GMII clock. :func:`receive` is what the receive MAC must make of a
burst of symbols; :func:`wire_frames` parses transmitted symbols back into frames.
"""

import random
import struct
import zlib

__all__ = [
    "with_fcs", "udp_frame", "frame_of_length", "wire", "idle", "receive", "RxResult", "counts",
    "split_frames", "wire_frames", "random_sizes", "seeded", "VERDICTS",
]

PREAMBLE, SFD = 0x55, 0xD5
MIN_FRAME = 64
VERDICTS = ("good", "bad_fcs", "rx_er", "runt", "oversize", "preamble")


def with_fcs(frame):
    return bytes(frame) + struct.pack("<I", zlib.crc32(frame))


def udp_frame(payload, *, dst="02:00:00:00:00:01", src="02:00:00:00:00:02"):
    """An Ethernet II / IPv4 / UDP frame carrying ``payload``, built by scapy (no FCS)."""
    from scapy.layers.inet import IP, UDP
    from scapy.layers.l2 import Ether
    from scapy.packet import Raw
    return bytes(Ether(dst=dst, src=src) / IP(src="10.0.0.2", dst="10.0.0.1")
                 / UDP(sport=5000, dport=5001) / Raw(load=bytes(payload)))


_UDP_OVERHEAD = 14 + 20 + 8


def frame_of_length(total, rng):
    """A scapy-built UDP frame of ``total`` bytes including its FCS, with a random payload;
    below the UDP header size (runts) the frame is cut short. Returns the frame with its FCS."""
    body = total - 4
    payload = rng.randbytes(max(0, body - _UDP_OVERHEAD))
    return with_fcs(udp_frame(payload)[:body])


def wire(frame, *, preamble=7, errors=(), sfd=True, preamble_bytes=None):
    """GMII symbols of ``frame`` (FCS included): preamble, SFD, the bytes. ``errors`` are
    indices into the returned symbols where ``er`` is set; ``preamble_bytes`` replaces the
    preamble wholesale (for bad preambles)."""
    head = bytes([PREAMBLE] * preamble) if preamble_bytes is None else bytes(preamble_bytes)
    raw = head + (bytes([SFD]) if sfd else b"") + bytes(frame)
    errors = set(errors)
    return [(b, 1, int(i in errors)) for i, b in enumerate(raw)]


def idle(cycles):
    return [(0, 0, 0)] * cycles


class RxResult:
    """What the receive MAC makes of one burst: the bytes it forwards (possibly none), whether
    they are flagged bad, and the verdict counted."""

    def __init__(self, data, verdict):
        self.data, self.verdict = bytes(data), verdict

    @property
    def bad(self):
        return self.verdict != "good"

    def __repr__(self):
        return f"RxResult({len(self.data)} bytes, {self.verdict})"


def _bursts(symbols):
    burst = []
    for d, dv, er in symbols:
        if dv:
            burst.append((d, er))
        elif burst:
            yield burst
            burst = []
    if burst:
        yield burst


def receive(symbols, max_frame=9018):
    """The receive MAC's reference: one :class:`RxResult` per burst of ``rx_dv``."""
    results = []
    for burst in _bursts(symbols):
        for i, (d, er) in enumerate(burst):
            if er:
                results.append(RxResult(b"", "rx_er"))
                break
            if d == SFD:
                body = bytes(b for b, _ in burst[i + 1:])
                errs = any(e for _, e in burst[i + 1:])
                n = len(body)
                if errs:
                    verdict = "rx_er"
                elif n > max_frame:
                    verdict = "oversize"
                elif n < MIN_FRAME:
                    verdict = "runt"
                elif with_fcs(body[:-4]) != body:
                    verdict = "bad_fcs"
                else:
                    verdict = "good"
                results.append(RxResult(body[:min(n, max_frame) - 4] if n > 4 else b"", verdict))
                break
            if d != PREAMBLE:
                results.append(RxResult(b"", "preamble"))
                break
        else:
            results.append(RxResult(b"", "preamble"))
    return results


def counts(results):
    tally = dict.fromkeys(VERDICTS, 0)
    for r in results:
        tally[r.verdict] += 1
    return tally


def split_frames(beats):
    """Stream transfers ``(data, last, user)`` -> list of ``(bytes, bad)``, one per ``last``."""
    frames, current = [], bytearray()
    for data, last, user in beats:
        current.append(data)
        if last:
            frames.append((bytes(current), bool(user)))
            current = bytearray()
    assert not current, f"{len(current)} bytes after the last frame's end"
    return frames


def wire_frames(symbols):
    """Transmitted symbols -> list of (frame with FCS, gap before it, any er) after checking the
    preamble is seven 0x55 and an SFD."""
    out, gap = [], 0
    for burst in _bursts_with_gaps(symbols):
        if burst is None:
            gap += 1
            continue
        raw = bytes(d for d, _ in burst)
        assert raw[:8] == bytes([PREAMBLE] * 7 + [SFD]), f"bad preamble {raw[:8].hex()}"
        out.append((raw[8:], gap, any(e for _, e in burst)))
        gap = 0
    return out


def _bursts_with_gaps(symbols):
    burst = []
    for d, en, er in symbols:
        if en:
            burst.append((d, er))
        else:
            if burst:
                yield burst
                burst = []
            yield None
    if burst:
        yield burst


def random_sizes(rng, count, low=64, high=1518, jumbo=()):
    """Frame sizes (FCS included): the extremes, then random ones, plus the given jumbo sizes."""
    sizes = [low, low + 1, high] + list(jumbo)
    sizes += [rng.randint(low, high) for _ in range(count - len(sizes))]
    return sizes


def seeded(seed):
    return random.Random(seed)
