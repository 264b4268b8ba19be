"""A 1000BASE-X link partner in plain Python, on :mod:`sim.models.pcs_model`'s encoder, decoder,
synchronisation and auto-negotiation models: the far end of the line in the SFP bench.

It imports nothing from ``gateware``. Its two halves run on two clocks, as a real PHY's do:

* :meth:`Partner.transmit_word`, once a cycle of its own clock: the next 10 bits of its line,
  first bit in bit 0. What it sends is what clause 36's transmit process sends for the
  auto-negotiation model's ``xmit``: /C/ ordered sets (/C1/ and /C2/ in turn) carrying the
  model's configuration word, /I/ (/I1/ after a positive running disparity, else /I2/), or its
  queued frames (/S/, preamble and SFD, the frame, /T/R/ and a second /R/ to end on an even
  code-group, then :data:`GAP_IDLES` /I/). The line starts ``offset`` bits into the first code-group's stream, and
  :meth:`slip` delays it one more bit (a comma slip at the board); a frame may be sent with one
  bit of one code-group inverted (a bit error).
* :meth:`Partner.receive_word`, once a cycle of its recovered clock: 10 bits of the board's
  line at whatever offset; the code-group boundary is the last comma's (K28.1/5/7's seven bits
  ``0011111`` or ``1100000``), decoded from the running disparity, fed to the synchronisation
  model, then to a receive process for /C/ (configuration words), /I/ and frames (/S/ to /T/,
  a frame with any invalid or control code-group in it is counted bad and not kept).
"""

import zlib

from .pcs_model import D2_2, D5_6, D16_2, D21_5, K28_5, AutoNeg, R, S, Sync, T, decode, encode

__all__ = ["Partner", "ABILITY", "PREAMBLE"]

#: The partner's base page: full duplex (bit 5), both pause bits (7, 8).
ABILITY = 0x01A0
PREAMBLE = bytes([0x55] * 7 + [0xD5])
#: /I/ ordered sets after a frame's /T/R/: with them the gap is at least the 12 bytes of a
#: MAC's inter-frame gap.
GAP_IDLES = 5
_COMMAS = ("0011111", "1100000")


def with_fcs(frame):
    """The frame with its FCS (IEEE 802.3 CRC-32, least significant byte first)."""
    return frame + zlib.crc32(frame).to_bytes(4, "little")


class Partner:
    """The link partner. ``link_timer`` in code-groups (one a cycle)."""

    def __init__(self, *, link_timer, ability=ABILITY, offset=0):
        self.an = AutoNeg(ability, link_timer)
        self.sync = Sync()
        # transmit
        self._rd, self._pending, self._bits, self._c1 = "-", [], "0" * offset, True
        self._frames, self.slips, self._gap = [], 0, 0
        self.sent = []
        # receive
        self._rx_bits, self._rx_rd, self._boundary_known = "", "-", False
        self._rx_state, self._held, self._frame, self._frame_bad = "IDLE", [], None, False
        self.frames, self.bad_frames, self.invalid, self.configs, self.realigns = [], 0, 0, [], 0
        self._restart = False

    # ---- transmit ------------------------------------------------------------------------------
    def send(self, frame, *, flip=None):
        """Queue ``frame`` (destination MAC to payload); the FCS is added. ``flip``: invert bit
        3 (``d``) of the code-group of that byte of the frame (from the destination MAC)."""
        self._frames.append((with_fcs(frame), flip))

    def slip(self):
        """Delay the line by one bit from now on."""
        self._bits = "0" + self._bits
        self.slips += 1

    def restart(self):
        """Restart auto-negotiation (mr_restart_an)."""
        self._restart = True

    def _ordered_set(self):
        """The next ordered set: ``[(byte, control, flip)]`` (``None`` for /I/'s second)."""
        if self.an.xmit == "CONFIGURATION":
            word = self.an.tx_config
            second, self._c1 = (D21_5 if self._c1 else D2_2), not self._c1
            return [(K28_5, 1, False), (second, 0, False), (word & 0xFF, 0, False), (word >> 8, 0, False)]
        if self.an.xmit == "DATA" and self._frames and not self._gap:
            body, flip = self._frames.pop(0)
            self.sent.append(body)
            self._gap = GAP_IDLES
            frame = PREAMBLE + body
            flipped = None if flip is None else len(PREAMBLE) + flip
            groups = [(S, 1, False)] + [(b, 0, n == flipped) for n, b in enumerate(frame) if n] \
                + [(T, 1, False), (R, 1, False)]
            if len(groups) % 2:
                groups.append((R, 1, False))
            return groups
        self._gap = max(0, self._gap - 1)
        return [(K28_5, 1, False), None]

    def _next_group(self):
        if not self._pending:
            self._pending = self._ordered_set()
        byte, control, flip = self._pending.pop(0) if self._pending[0] is not None else (None, 0, False)
        if byte is None:            # the /I/'s second code-group follows the K28.5's disparity
            self._pending.pop(0)
            byte = D5_6 if self._rd == "+" else D16_2
        code, self._rd = encode(byte, control, self._rd)
        if flip:
            code = code[:3] + ("1" if code[3] == "0" else "0") + code[4:]
        return code

    def transmit_word(self):
        """The next 10 bits of the line, first bit in bit 0."""
        while len(self._bits) < 10:
            self._bits += self._next_group()
        word, self._bits = self._bits[:10], self._bits[10:]
        return sum(int(bit) << i for i, bit in enumerate(word))

    # ---- receive -------------------------------------------------------------------------------
    def receive_word(self, word):
        """Take 10 received bits (first in bit 0)."""
        self._rx_bits += "".join(str(word >> i & 1) for i in range(10))
        while len(self._rx_bits) >= 17:
            commas = [p for p in range(10) if self._rx_bits[p:p + 7] in _COMMAS]
            if commas and commas[0] != 0:
                self._rx_bits = self._rx_bits[commas[0]:]
                self.realigns += 1
                continue
            code, self._rx_bits = self._rx_bits[:10], self._rx_bits[10:]
            self._group(code)

    def _group(self, code):
        byte, control, code_error, disparity_error, self._rx_rd = decode(code, self._rx_rd)
        invalid = code_error or disparity_error
        self.invalid += invalid
        synced = self.sync.step(byte, control, invalid)
        word, idle = None, False
        key = None if invalid else (byte, control)
        state = self._rx_state
        if state == "FRAME":
            if key == (T, 1):
                if self._frame_bad:
                    self.bad_frames += 1
                else:
                    self.frames.append(bytes(self._frame))
                self._rx_state = "IDLE"
            elif key is not None and not control:
                self._frame.append(byte)
            else:
                self._frame_bad = True
                if key == (K28_5, 1):
                    self.bad_frames += 1
                    self._rx_state = "K"
        elif state == "CONFIG":
            self._held.append(byte)
            if len(self._held) == 3:
                word = self._held[1] | self._held[2] << 8
                self.configs.append(word)
                self._rx_state = "IDLE"
        elif state == "K":
            if key in ((D21_5, 0), (D2_2, 0)):
                self._rx_state, self._held = "CONFIG", [byte]
            else:
                idle = key in ((D5_6, 0), (D16_2, 0))
                self._rx_state = "IDLE"
        elif key == (K28_5, 1):
            self._rx_state = "K"
        elif key == (S, 1):
            self._rx_state, self._frame, self._frame_bad = "FRAME", bytearray([0x55]), False
        restart, self._restart = self._restart, False
        self.an.step(word=word, idle=idle, invalid=invalid, sync_status=synced, restart=restart)

    @property
    def link_ok(self):
        return self.an.state == "LINK_OK"


