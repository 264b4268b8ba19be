"""GMII receive streams as the PHY presents them: preamble, SFD, frame, FCS, inter-frame gap.

Frames are given without FCS (as scapy builds them); :func:`wire_bytes` adds the FCS
(``zlib.crc32``, an independent oracle for the MAC's ``lib.crc``). :func:`replay_file` writes the
two-bytes-per-cycle file that ``sim/hdl/gmii_replay.v`` plays.
"""

import struct
import zlib

__all__ = ["fcs", "wire_bytes", "cycles", "replay_file", "PREAMBLE", "MIN_GAP"]

PREAMBLE = b"\x55" * 7 + b"\xd5"
MIN_GAP = 12


def fcs(frame):
    return struct.pack("<I", zlib.crc32(frame) & 0xFFFFFFFF)


def wire_bytes(frame, *, pad=True):
    """Frame (no FCS) -> bytes after the SFD: padded to 60 bytes, then the FCS."""
    if pad and len(frame) < 60:
        frame = frame + bytes(60 - len(frame))
    return frame + fcs(frame)


def cycles(frames, *, gap=MIN_GAP, preamble=PREAMBLE, errors=None):
    """(dv, er, byte) per GMII cycle for ``frames``; ``errors`` maps (frame index, byte offset
    from the preamble's start) to a cycle with RX_ER set."""
    errors = errors or {}
    out = []
    for i, frame in enumerate(frames):
        for offset, byte in enumerate(preamble + wire_bytes(frame)):
            out.append((1, int((i, offset) in errors), byte))
        out.extend([(0, 0, 0)] * gap)
    return out


def replay_file(path, frames, **kwargs):
    """Write the replay file for ``frames``; returns the number of GMII cycles in it."""
    stream = cycles(frames, **kwargs)
    data = bytearray()
    for dv, er, byte in stream:
        data += bytes((dv | (er << 1), byte))
    with open(path, "wb") as f:
        f.write(data)
    return len(stream)
