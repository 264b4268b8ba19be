"""A 1000BASE-X PCS (IEEE 802.3 clause 36) in plain Python: the oracle of the PCS tests.

Written from the standard apart from the gateware, and with other tables: here both columns of
Tables 36-1a, 36-1b and 36-2 are written out (``(RD-, RD+)``), the alternate D.x.A7 is chosen by
the run-length rule it exists for (no five equal bits across ``e i f g h``), and code-groups are
strings ``abcdeifghj``. It imports nothing from ``gateware``.

Here: 8b/10b with running disparity (:func:`encode`, :func:`decode`), the ordered sets a
transmitter sends for GMII bytes (:func:`transmit`), the GMII bytes a receiver gives for
code-groups (:func:`receive`), the synchronisation state machine of figure 36-9
(:class:`Sync`), and clause 37's auto-negotiation state machine of figure 37-6
(:class:`AutoNeg`).
"""

__all__ = ["encode", "decode", "to_int", "to_bits", "CONTROLS", "Sync", "AutoNeg", "transmit", "receive",
           "bit_stream"]

#: Table 36-1a: EDCBA -> abcdei, (RD-, RD+).
SIX = {
    0: ("100111", "011000"), 1: ("011101", "100010"), 2: ("101101", "010010"), 3: ("110001", "110001"),
    4: ("110101", "001010"), 5: ("101001", "101001"), 6: ("011001", "011001"), 7: ("111000", "000111"),
    8: ("111001", "000110"), 9: ("100101", "100101"), 10: ("010101", "010101"), 11: ("110100", "110100"),
    12: ("001101", "001101"), 13: ("101100", "101100"), 14: ("011100", "011100"), 15: ("010111", "101000"),
    16: ("011011", "100100"), 17: ("100011", "100011"), 18: ("010011", "010011"), 19: ("110010", "110010"),
    20: ("001011", "001011"), 21: ("101010", "101010"), 22: ("011010", "011010"), 23: ("111010", "000101"),
    24: ("110011", "001100"), 25: ("100110", "100110"), 26: ("010110", "010110"), 27: ("110110", "001001"),
    28: ("001110", "001110"), 29: ("101110", "010001"), 30: ("011110", "100001"), 31: ("101011", "010100"),
}
#: Table 36-1b: HGF -> fghj, (RD-, RD+); 7 is D.x.P7; ``A7`` the alternate.
FOUR = {
    0: ("1011", "0100"), 1: ("1001", "1001"), 2: ("0101", "0101"), 3: ("1100", "0011"),
    4: ("1101", "0010"), 5: ("1010", "1010"), 6: ("0110", "0110"), 7: ("1110", "0001"),
}
A7 = ("0111", "1000")
#: Table 36-2, whole code-groups (RD-, RD+).
K_CODES = {
    "K28.0": ("0011110100", "1100001011"), "K28.1": ("0011111001", "1100000110"),
    "K28.2": ("0011110101", "1100001010"), "K28.3": ("0011110011", "1100001100"),
    "K28.4": ("0011110010", "1100001101"), "K28.5": ("0011111010", "1100000101"),
    "K28.6": ("0011110110", "1100001001"), "K28.7": ("0011111000", "1100000111"),
    "K23.7": ("1110101000", "0001010111"), "K27.7": ("1101101000", "0010010111"),
    "K29.7": ("1011101000", "0100010111"), "K30.7": ("0111101000", "1000010111"),
}


def _byte(name):
    x, y = name[1:].split(".")
    return int(y) << 5 | int(x)


#: The control bytes, by name.
CONTROLS = {name: _byte(name) for name in K_CODES}
K28_5, S, T, R, V = (CONTROLS[n] for n in ("K28.5", "K27.7", "K29.7", "K23.7", "K30.7"))
#: The second code-group of /I1/, /I2/, /C1/, /C2/ (clause 36.2.4.12, 36.2.4.10).
D5_6, D16_2, D21_5, D2_2 = 0xC5, 0x50, 0xB5, 0x42


def _rd(block, before):
    """Running disparity ('-' or '+') after a sub-block (clause 36.2.4.4)."""
    ones, zeros = block.count("1"), block.count("0")
    if ones > zeros or block in ("000111", "0011"):
        return "+"
    if zeros > ones or block in ("111000", "1100"):
        return "-"
    return before


def encode(byte, control, rd):
    """``(code-group string abcdeifghj, running disparity after)`` from running disparity ``rd``
    ('-' or '+')."""
    column = 0 if rd == "-" else 1
    if control:
        name = next(n for n, b in CONTROLS.items() if b == byte)
        code = K_CODES[name][column]
        return code, _rd(code[6:], _rd(code[:6], rd))
    six = SIX[byte & 31][column]
    middle = _rd(six, rd)
    four = FOUR[byte >> 5][0 if middle == "-" else 1]
    if byte >> 5 == 7 and six[-2:] == four[0] * 2:
        four = A7[0 if middle == "-" else 1]
    return six + four, _rd(four, middle)


def to_int(code):
    """A code-group string as the gateware holds it: ``a`` in bit 0."""
    return sum(int(bit) << i for i, bit in enumerate(code))


def to_bits(value):
    return "".join(str(value >> i & 1) for i in range(10))


def _table():
    table = {}
    for control, bytes_ in ((0, range(256)), (1, CONTROLS.values())):
        for byte in bytes_:
            for rd in "-+":
                code, _ = encode(byte, control, rd)
                table.setdefault(code, {})[rd] = (byte, control)
    return table


_TABLE = _table()


def decode(code, rd):
    """Decode a code-group string from running disparity ``rd``: ``(byte, control, code_error,
    disparity_error, rd after)``. The running disparity after is worked out from the bits."""
    after = _rd(code[6:], _rd(code[:6], rd))
    columns = _TABLE.get(code)
    if columns is None:
        return 0, 0, True, False, after
    byte, control = columns.get(rd) or next(iter(columns.values()))
    return byte, control, False, rd not in columns, after


def is_comma(byte, control):
    return bool(control) and byte in (CONTROLS["K28.1"], K28_5, CONTROLS["K28.7"])


class Sync:
    """Figure 36-9, one code-group at a time: ``step(byte, control, invalid)`` -> ``sync_status``.

    A code-group is good when valid and not a comma in an odd position; the counter of good
    code-groups lets the machine climb back one step for every four good code-groups in a row."""

    def __init__(self):
        self.state, self.even, self.good, self.losses = "LOSS_OF_SYNC", False, 0, 0

    @property
    def synced(self):
        return self.state.startswith("SYNC_ACQUIRED")

    def step(self, byte, control, invalid):
        comma = not invalid and is_comma(byte, control)
        data = not invalid and not control
        bad = invalid or (comma and self.even)
        state, was = self.state, self.synced
        if state == "LOSS_OF_SYNC":
            nxt = "COMMA_DETECT_1" if comma else state
        elif state.startswith("COMMA_DETECT"):
            nxt = f"ACQUIRE_SYNC_{state[-1]}" if data else "LOSS_OF_SYNC"
            if data and state[-1] == "3":
                nxt = "SYNC_ACQUIRED_1"
        elif state.startswith("ACQUIRE_SYNC"):
            if bad:
                nxt = "LOSS_OF_SYNC"
            elif comma:
                nxt = f"COMMA_DETECT_{int(state[-1]) + 1}"
            else:
                nxt = state
        else:
            level = int(state[len("SYNC_ACQUIRED_")])
            if bad:
                nxt = "LOSS_OF_SYNC" if level == 4 else f"SYNC_ACQUIRED_{level + 1}"
            elif level == 1:
                nxt = state
            elif state.endswith("A") and self.good == 3:
                nxt = f"SYNC_ACQUIRED_{level - 1}"
            else:
                nxt = f"SYNC_ACQUIRED_{level}A"
        # the entry actions of the state entered
        self.even = True if nxt.startswith("COMMA_DETECT") else not self.even
        if nxt.startswith("SYNC_ACQUIRED") and nxt[-1] != "A":
            self.good = 0
        elif nxt.endswith("A"):
            self.good += 1
        self.state = nxt
        if was and not self.synced:
            self.losses += 1
        return self.synced


def transmit(gmii, rd="-"):
    """Code-group strings for GMII ``(tx_en, tx_er, txd)`` per cycle (figures 36-5 and 36-6):
    /I/ between frames (/I1/ when the running disparity is positive), /S/ for the first byte of a
    frame that starts at an even code-group (else that byte is lost and the next is /S/), the
    data, /V/ for ``tx_er``, and /T/R/ (/T/R/R/ to end on an odd code-group) after it."""
    out, even, state = [], True, "IDLE"

    def send(byte, control):
        nonlocal rd, even
        code, rd = encode(byte, control, rd)
        out.append(code)
        even = not even

    idle_d = None
    for en, er, d in gmii:
        if idle_d is not None:
            send(idle_d, 0)
            idle_d = None
        elif state == "IDLE" and en and not er:
            send(S, 1)
            state = "DATA"
        elif state == "DATA" and en:
            send(V if er else d, 1 if er else 0)
        elif state == "DATA":
            send(T, 1)
            state = "END"
        elif state == "END":
            send(R, 1)
            state = "IDLE" if even else "ALIGN"
        elif state == "ALIGN":
            send(R, 1)
            state = "IDLE"
        else:
            positive = rd == "+"
            send(K28_5, 1)
            idle_d = D5_6 if positive else D16_2
    return out


def receive(groups):
    """GMII ``(rx_dv, rx_er, rxd)`` per decoded code-group ``(byte, control, invalid)`` of a link
    in sync whose first code-group is even (figure 36-7b, without carrier extension, false carrier
    or the look-ahead past /T/): /S/ gives 0x55, data in a frame gives itself, /T/ and the idles
    give ``rx_dv`` low, K28.5 in an even position in a frame ``rx_er`` and the end of the frame,
    anything else in a frame ``rx_er``. Also the configuration words of /C/ ordered sets received."""
    out, configs, state, held = [], [], "IDLE", []
    for n, (byte, control, invalid) in enumerate(groups):
        code = (byte, control) if not invalid else None
        if state == "FRAME":
            if code == (T, 1):
                out.append((0, 0, 0))
                state = "IDLE"
            elif code == (K28_5, 1) and n % 2 == 0:
                out.append((1, 1, byte))
                state = "K"
            elif code is not None and not control:
                out.append((1, 0, byte))
            else:
                out.append((1, 1, byte))
            continue
        out.append((0, 0, 0))
        if state == "CONFIG":
            held.append(byte)
            if len(held) == 3:
                configs.append(held[1] | held[2] << 8)
                state = "IDLE"
        elif state == "K":
            state, held = ("CONFIG", [byte]) if code in ((D21_5, 0), (D2_2, 0)) else ("IDLE", [])
        elif code == (K28_5, 1):
            state = "K"
        elif code == (S, 1):
            out[-1] = (1, 0, 0x55)
            state = "FRAME"
    return out, configs


def bit_stream(codes, slip):
    """The line's bits as 10-bit words (first bit in bit 0), ``slip`` bits late: ``slip`` zero
    bits, then the code-groups' bits."""
    bits = "0" * slip + "".join(codes)
    bits += "0" * (-len(bits) % 10)
    return [to_int(bits[i:i + 10]) for i in range(0, len(bits), 10)]


class AutoNeg:
    """Figure 37-6 (clause 37.3.1), base page only, one cycle at a time: :meth:`step` with what
    the receive process indicated in the cycle (a config word, an /I/, an invalid code-group),
    ``sync_status`` and ``mr_restart_an``, gives the state after it.

    The match functions (clause 37.3.1.4) are read from the words received since the last /I/:
    ``ability_match`` when the last three agree but for ACK (bit 14), ``acknowledge_match`` when
    they are equal and have ACK; ``consistency_match`` when the last agrees, ACK aside, with the
    one ability_match held for on the way into ACKNOWLEDGE_DETECT; ``idle_match`` after three /I/
    with no word between. A state's exits are tested with what was received before the cycle;
    the link timer is done ``link_timer`` cycles after the cycle that entered a state starting it.
    RUDI(INVALID) restarts only while ``xmit`` is not DATA. No next pages."""

    ACK = 1 << 14

    def __init__(self, ability, link_timer, enable=True):
        self.ability, self.link_timer, self.enable = ability, link_timer, enable
        self.state, self.xmit, self.tx_config = "AN_ENABLE", "CONFIGURATION" if enable else "IDLE", 0
        self.words, self.idles, self.held, self.timer = [], 0, None, 0
        self.lp_ability, self.complete, self.restarts = 0, False, 0

    def _same(self, a, b):
        return (a ^ b) & ~self.ACK == 0

    def _matches(self):
        last = self.words[-3:]
        ability = len(last) == 3 and all(self._same(w, last[0]) for w in last)
        acknowledge = len(last) == 3 and all(w == last[0] and w & self.ACK for w in last)
        consistency = bool(last) and self.held is not None and self._same(last[-1], self.held)
        zero = bool(last) and last[-1] == 0
        return ability, acknowledge, consistency, self.idles >= 3, zero

    def _next(self, sync_status, restart, invalid):
        if restart or not sync_status or (invalid and self.xmit != "DATA"):
            return "AN_ENABLE"
        ability, acknowledge, consistency, idle, zero = self._matches()
        done = self.timer == self.link_timer
        state = self.state
        if state == "AN_ENABLE":
            return "AN_RESTART" if self.enable else "AN_DISABLE_LINK_OK"
        if state == "AN_DISABLE_LINK_OK":
            return "AN_ENABLE" if self.enable else state
        if state == "AN_RESTART":
            return "ABILITY_DETECT" if done else state
        if state == "ABILITY_DETECT":
            if ability and not zero:
                self.held = self.words[-1]
                return "ACKNOWLEDGE_DETECT"
            return state
        if state == "LINK_OK":
            return "AN_ENABLE" if ability else state
        if ability and zero or (state == "ACKNOWLEDGE_DETECT" and acknowledge and not consistency):
            return "AN_ENABLE"
        if state == "ACKNOWLEDGE_DETECT":
            return "COMPLETE_ACKNOWLEDGE" if acknowledge else state
        if state == "COMPLETE_ACKNOWLEDGE":
            return "IDLE_DETECT" if done else state
        return "LINK_OK" if idle and done else state  # IDLE_DETECT

    def step(self, *, word=None, idle=False, invalid=False, sync_status=True, restart=False):
        nxt = self._next(sync_status, restart, invalid)
        if nxt != self.state:
            if nxt in ("AN_RESTART", "COMPLETE_ACKNOWLEDGE", "IDLE_DETECT"):
                self.timer = -1
            self.restarts += nxt == "AN_ENABLE"
            if nxt == "COMPLETE_ACKNOWLEDGE":
                self.lp_ability = self.words[-1]
        self.timer = min(self.timer + 1, self.link_timer)
        self.state, self.complete = nxt, nxt == "LINK_OK"
        self.xmit, self.tx_config = {
            "AN_ENABLE": ("CONFIGURATION" if self.enable else "IDLE", 0), "AN_RESTART": ("CONFIGURATION", 0),
            "ABILITY_DETECT": ("CONFIGURATION", self.ability),
            "ACKNOWLEDGE_DETECT": ("CONFIGURATION", self.ability | self.ACK),
            "COMPLETE_ACKNOWLEDGE": ("CONFIGURATION", self.ability | self.ACK),
            "IDLE_DETECT": ("IDLE", self.tx_config), "LINK_OK": ("DATA", self.tx_config),
            "AN_DISABLE_LINK_OK": ("DATA", self.tx_config)}[nxt]
        if word is not None:
            self.words, self.idles = self.words[-2:] + [word], 0
        elif idle:
            self.words, self.idles = [], self.idles + 1
        return nxt
