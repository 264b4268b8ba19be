"""A UDP client for the projector: sends frames and control records, asks for status.

What it does for the user:

* **Record size.** Records must travel unfragmented (the projector drops fragments). The client
  sends with the don't-fragment flag, takes the path MTU the operating system knows for the
  projector (or the ``mtu`` it is given) and sizes image records to fill it: 1,462 pixels a
  record on an ordinary 1,500-byte MTU, 8,962 on a jumbo path (a delta frame's records, 1,458
  and 8,958). A record that does not fit (the
  path turned out narrower, or ``mtu`` was too large) raises :class:`ClientError` saying so.
* **Frame ids.** Before its first frame the client reads a status reply and continues after the
  newest frame id the projector has handed on, so a restarted sender is never refused as old
  (see ``docs/protocol.md``, Frame ids).
* **Bit depth.** Each frame goes at the smallest bit depth that shows it within a tolerance,
  rounded to the nearest level (:mod:`host.levels`); a control record sets the depth when it
  changes. The rounding error is reported.
* **Delta frames.** Asked to (``delta``), it sends an image as a delta frame of the key frame,
  the last whole frame it sent: only the rows that differ from it once rounded to the key's bit
  depth (a delta shows at its base's depth). An image that changed in more rows than asked, or
  that the key's depth does not show within the tolerance, goes whole and becomes the key.
* **Checks.** With ``check`` (the default), after each frame a status reply must show every
  record taken and every row handed on; otherwise :class:`ClientError` says what the projector
  counted instead (fragments, overflow, refused rows, ...). A delta the projector refused because
  it no longer holds the key frame is sent again as a whole frame.

:class:`MasterClient` talks to the sync master of a tiled display over the same link: it sets
the master's trigger in seconds, refusing before it sends what the master would drop, fires
software triggers and reads its status.
"""

import dataclasses
import errno
import socket
import sys
import time

import numpy as np

from spec import records
from spec.records import RecordType
from spec.registers import TriggerMode

from . import codec, levels

__all__ = ["Client", "MasterClient", "ClientError", "Sent", "DEFAULT_PORT", "DELTA_ROWS", "path_mtu", "period_fault"]

DEFAULT_PORT = 5000
#: A starting point for ``delta``: a delta then sends at most half a whole frame's pixels; an
#: image that changed more goes whole and becomes a fresh key, likely closer to the images after it.
DELTA_ROWS = 0.5

# Linux socket options (Python's socket module does not name them): the don't-fragment policy
# and the path MTU of a connected socket.
_IP_MTU_DISCOVER, _IP_PMTUDISC_DO, _IP_MTU = 10, 2, 14

#: Counters that say why records or rows went missing, with what each means for a sender.
_WHY = {
    "drop_ip_fragment": "the records were fragmented on the way (the path's MTU is smaller than the "
                        "records: give a smaller mtu)",
    "drop_overflow": "the projector's receive buffer overflowed (send slower: rate)",
    "mac_rx_dropped": "the projector's receive FIFO overflowed (send slower: rate)",
    "drop_ip_length": "frames arrived shorter than their IP length",
    "drop_ip_checksum": "frames arrived with a bad IP checksum",
    "drop_udp_checksum": "datagrams arrived with a bad UDP checksum",
    "drop_udp_length": "datagrams arrived with a bad UDP length",
    "mac_bad_fcs": "frames arrived with a bad FCS (the link is damaging them)",
    "drop_app_version": "the projector speaks another protocol version",
    "drop_app_rows": "the image does not fit the projector's DMD",
    "drop_app_length": "records were malformed",
    "rows_incomplete": "records were lost or reordered on the way, so rows they split were dropped",
    "store_rows_refused": "the projector's store refused rows (a frame id not newer than its newest, "
                          "no free slot, or a delta without its base)",
    "store_rows_no_base": "the projector no longer holds the whole frame a delta is based on "
                          "(send a whole frame: later deltas can use it)",
}


def period_fault(plan):
    """Why a :func:`spec.schedule.plan` with a periodic trigger cannot keep its period (``None``
    when it can): a period shorter than the plan's shortest trigger period for the bit depth
    planned (its frame period, and a cycle for a trigger on an odd cycle). The projector takes
    such a period (it knows a frame's depth only when the frame comes); each frame then outlasts
    it, the strobe that comes meanwhile is held or lost, and ``frames_period_short`` counts the
    frames."""
    p = plan.params
    if p.trigger != TriggerMode.PERIODIC or p.period >= plan.trigger_cycles:
        return None
    return (f"a periodic trigger every {p.period} cycles is shorter than the plan's trigger period of "
            f"{plan.trigger_cycles} cycles ({plan.rate_hz:.1f} frames/s): every frame would outlast it")


def _planes_missing(depth, skip, frame_depth):
    """Why an entry showing ``depth`` planes below the ``skip`` most significant cannot be shown
    of a frame of ``frame_depth`` bits (None if it can): the projector's rule
    (``docs/protocol.md``, Sequence entry record)."""
    if depth + skip > 8:
        return f"depth {depth} below {skip} planes left out is more than the 8 bits a frame has"
    if depth == 0 or (skip == 0 and depth >= frame_depth):
        if skip >= frame_depth:
            return f"skip {skip} leaves no plane of its {frame_depth}-bit frame"
    elif skip + depth > frame_depth:
        return f"depth {depth} below {skip} planes left out is more than its {frame_depth}-bit frame has"
    return None


class ClientError(RuntimeError):
    """The projector did not answer, refused or lost what was sent, or cannot be reached as asked.

    Attributes
    ----------
    counters : dict
        For a frame the projector did not take: how much each counter that says why grew.
    """

    def __init__(self, message, counters=None):
        super().__init__(message)
        self.counters = counters or {}


@dataclasses.dataclass
class Sent:
    """One frame sent: its id, bit depth, records, the rounding error left (8-bit LSB), the rows
    it carried and, for a delta frame, its base (the key frame's id; None for a whole frame).
    ``refused``: why the projector refused the delta this whole frame was sent in place of (None
    when it refused none)."""
    frame: int
    depth: int
    records: int
    error_lsb: float
    rows: int
    base: int | None = None
    refused: str | None = None

    @property
    def delta(self):
        return self.base is not None


def path_mtu(sock):
    """The path MTU the operating system knows for a connected socket (None where it cannot tell)."""
    if not sys.platform.startswith("linux"):
        return None
    try:
        return sock.getsockopt(socket.IPPROTO_IP, _IP_MTU)
    except OSError:
        return None


class _Link:
    """What a client of any of the protocol's devices does: a connected UDP socket that sends
    with the don't-fragment flag, paced; record sequence numbers; the status query, answered by
    a record of type :attr:`_REPLY` (a subclass's)."""

    _REPLY = None

    def __init__(self, address, port=DEFAULT_PORT, *, timeout=1.0, rate=None, mtu=None, bind=("0.0.0.0", 0)):
        self.peer = (address, port)
        self.timeout = timeout
        self.rate = rate
        self.sequence = 0
        self._sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        try:
            self._sock.bind(bind)
            if sys.platform.startswith("linux"):
                self._sock.setsockopt(socket.IPPROTO_IP, _IP_MTU_DISCOVER, _IP_PMTUDISC_DO)
            self._sock.connect(self.peer)
        except OSError as error:
            self._sock.close()
            raise ClientError(f"cannot reach {address}:{port}: {error}") from error
        self._sock.settimeout(timeout)
        self.mtu = mtu or path_mtu(self._sock) or 1500
        self._paced_since = None
        self._paced_bytes = 0
        self._last = None          # the last status reply read

    def close(self):
        self._sock.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def _next(self):
        sequence = self.sequence
        self.sequence = (self.sequence + 1) & codec.SEQUENCE_MASK
        return sequence

    def _pace(self, size):
        if not self.rate:
            return
        now = time.monotonic()
        if self._paced_since is None:
            self._paced_since = now
        ahead = self._paced_since + self._paced_bytes / self.rate - now
        if ahead > 0:
            time.sleep(ahead)
        elif ahead < -0.1:
            # idle for a while: do not burst to catch up
            self._paced_since, self._paced_bytes = now, 0
        self._paced_bytes += size

    def _send(self, record):
        self._pace(len(record))
        try:
            self._sock.send(record)
        except OSError as error:
            if error.errno == errno.EMSGSIZE:
                known = path_mtu(self._sock)
                raise ClientError(
                    f"a {len(record)}-byte record does not fit the path to {self.peer[0]} without "
                    f"fragmenting (the records are sized for an MTU of {self.mtu} bytes; the path's is "
                    f"{known or 'smaller'}): give mtu={known or 'the path MTU'}") from error
            raise ClientError(f"cannot send to {self.peer[0]}:{self.peer[1]}: {error}") from error

    def send_records(self, encoded):
        """Send already encoded records (their sequence numbers are kept)."""
        for record in encoded:
            self._send(record)
        return len(encoded)

    # -- status ------------------------------------------------------------------------------

    def status(self, retries=2):
        """Ask for a status reply (the device's: a projector's, a sync master's) and return its
        fields as a dict."""
        for _attempt in range(retries + 1):
            sequence = self._next()
            self._send(codec.status_query(sequence))
            deadline = time.monotonic() + self.timeout
            while (left := deadline - time.monotonic()) > 0:
                self._sock.settimeout(left)
                try:
                    raw = self._sock.recv(65536)
                except socket.timeout:
                    break
                except OSError as error:
                    raise ClientError(f"no status from {self.peer[0]}:{self.peer[1]}: {error}") \
                        from error
                try:
                    head, body, _rest = codec.decode(raw)
                except codec.ProtocolError as error:
                    raise ClientError(f"bad status reply from {self.peer[0]}:{self.peer[1]}: {error}") \
                        from error
                if head["type"] == self._REPLY and head["sequence"] == sequence:
                    self._last = body
                    return body
        raise ClientError(f"no status reply from {self.peer[0]}:{self.peer[1]} "
                          f"after {retries + 1} tries of {self.timeout} s")


class Client(_Link):
    """Talks to one projector.

    Parameters
    ----------
    address : str
        The projector's IPv4 address.
    port : int
        Its UDP port.
    timeout : float
        Seconds to wait for a status reply.
    rate : float or None
        Pacing: at most this many bytes of records per second (None: as fast as the socket
        takes them). The gateware keeps up with a full gigabit line; pacing protects switches
        and the host's own buffers.
    mtu : int or None
        IP MTU of the path to the projector; default: what the operating system knows (the
        route's MTU, lowered by any ICMP "fragmentation needed" it has seen), else 1,500.
    check : bool
        After each frame, read a status reply and raise :class:`ClientError` if the projector
        did not take every record and hand on every row.
    """

    _REPLY = RecordType.STATUS_REPLY

    def __init__(self, address, port=DEFAULT_PORT, *, timeout=1.0, rate=None, mtu=None, check=True,
                 bind=("0.0.0.0", 0)):
        super().__init__(address, port, timeout=timeout, rate=rate, mtu=mtu, bind=bind)
        self.check = check
        self.limit = records.record_limit(self.mtu)
        if self.limit <= records.DELTA_HEADER:
            self.close()
            raise ClientError(f"an MTU of {self.mtu} bytes leaves no room for pixels")
        self._depth = None         # the bit depth this client last set
        self._next_frame = None    # the frame id to send next (known after the first status)
        self._key = None           # the last whole frame sent, (id, Quantised): the base of deltas

    # -- frames ------------------------------------------------------------------------------

    def next_frame(self):
        """The frame id the next frame gets: after the newest the projector has handed on (read
        from a status reply the first time), then counting up."""
        if self._next_frame is None:
            self._next_frame = (self.status()["newest_frame"] + 1) & 0xFFFF
        return self._next_frame

    def send_image(self, image, frame=None, *, depth=None, tolerance=0.5, delta=0.0):
        """Send one image as a frame.

        Parameters
        ----------
        image : array_like
            Rows x columns, the DMD's geometry: 8-bit (``uint8``) or real targets in 0..255.
        frame : int, optional
            Frame id; default :meth:`next_frame`. An id the projector does not take as newer
            than its newest is refused by it (and, with ``check``, raises).
        depth : int, optional
            Bit depth; default the smallest within ``tolerance`` (8-bit LSB) of every target.
        delta : float
            0 (the default): a whole frame. Otherwise a delta frame of the key frame (the last
            whole frame sent), carrying only the rows that differ from it, when they are at most
            this fraction of the rows (e.g. :data:`DELTA_ROWS`) and the key's bit depth shows the
            image (within ``tolerance``, or no worse than its own depth; with ``depth``, only a
            key of that depth); else a whole frame, which becomes the key. A delta carries a row
            at least: an image equal to the key goes as a delta of its first row.

        Returns
        -------
        Sent
            With ``check``, a delta the projector refused for want of its base
            (``store_rows_no_base``) is sent again as a whole frame with the next id: that
            frame's, saying why in ``refused``.
        """
        frame = self.next_frame() if frame is None else frame & 0xFFFF
        image = np.asarray(image)
        before = self._last if self.check else None
        if self.check and before is None:
            before = self.status()
        if before is not None:
            self._fits(image, before)
        shown = levels.quantise(image, depth, tolerance=tolerance)
        keyed = self._against_key(image, shown, depth is not None, tolerance, delta)
        base, rows = None, None
        if keyed is not None:
            shown, rows = keyed
            base = self._key[0]
        elif shown.depth != self._depth:
            # a delta takes its depth from its base: only a whole frame needs the control record
            self.control(bit_depth=shown.depth)
            self._depth = shown.depth
        encoded = codec.image_records(shown.data, frame, sequence=self.sequence, limit=self.limit,
                                      base=base, rows=rows)
        self.sequence = (self.sequence + len(encoded)) & codec.SEQUENCE_MASK
        self.send_records(encoded)
        self._next_frame = (frame + 1) & 0xFFFF
        carried = image.shape[0] if rows is None else len(rows)
        if self.check:
            try:
                self._verify(before, len(encoded), carried, frame)
            except ClientError as error:
                if base is None or not error.counters.get("store_rows_no_base"):
                    raise
                self._key = None
                whole = self.send_image(image, depth=depth, tolerance=tolerance, delta=delta)
                return dataclasses.replace(whole, refused=str(error))
        if base is None:
            self._key = (frame, shown)
        return Sent(frame=frame, depth=shown.depth, records=len(encoded), error_lsb=shown.error_lsb,
                    rows=carried, base=base)

    def _against_key(self, image, shown, fixed, tolerance, delta):
        """The image as a delta of the key frame, ``(Quantised at the key's depth, rows to carry)``;
        None when it is due as a whole frame. ``shown``: the image at its own depth (``fixed``:
        the depth the caller asked for)."""
        if not delta or self._key is None:
            return None
        key = self._key[1]
        if fixed and shown.depth != key.depth:
            return None
        at_key = shown if shown.depth == key.depth else levels.quantise(image, key.depth)
        # the delta shows at the key's depth: only if that shows the image as its own depth would
        if at_key.error_lsb > max(tolerance, shown.error_lsb):
            return None
        # rows compared as sent: the bytes of equal levels are equal
        rows = codec.changed_rows(at_key.data, key.data)
        if len(rows) > delta * image.shape[0]:
            return None
        return at_key, rows if len(rows) else np.array([0])

    def send_sequence(self, images, first_frame=None, **kwargs):
        """Several images as consecutive frames; returns a :class:`Sent` for each."""
        # ids after the first from next_frame: they count on past a delta sent again whole
        return [self.send_image(image, first_frame if i == 0 else None, **kwargs) for i, image in enumerate(images)]

    @staticmethod
    def _fits(image, status):
        geometry = (status["dmd_rows"], status["dmd_columns"])
        if image.shape != geometry:
            raise ClientError(f"the image is {image.shape[1]}x{image.shape[0]}, the projector's DMD "
                              f"{geometry[1]}x{geometry[0]}")

    def _verify(self, before, sent, rows, frame):
        """Wait (at most ``timeout``) until a status reply shows ``sent`` more image records and
        ``rows`` more rows handed on than ``before`` (the rows the frame carried: a delta's own),
        none refused by the store; else raise with the counters that say why. (A frame's first
        row is the one a stale id gets refused, long before its last row is handed on.)"""
        deadline = time.monotonic() + self.timeout
        while True:
            after = self.status()
            took, handed = (after[name] - before[name] for name in ("records_image", "rows"))
            if took >= sent and handed >= rows or time.monotonic() > deadline:
                break
            time.sleep(0.001)
        refused = after["store_rows_refused"] - before["store_rows_refused"]
        if took >= sent and handed >= rows and not refused:
            return
        grew = {name: after[name] - before[name] for name in _WHY if after[name] != before[name]}
        why = "; ".join(f"{name} +{count}: {_WHY[name]}" for name, count in grew.items()) or \
            "no counter says why (the records did not reach the projector)"
        raise ClientError(f"frame {frame}: the projector took {took} of {sent} records and handed on {handed} "
                          f"of {rows} rows; {why}. Its newest frame id is {after['newest_frame']}, "
                          f"it shows frame {after['shown_frame']}", grew)

    # -- settings and status -----------------------------------------------------------------

    def control(self, *, software_trigger=False, **config):
        """Set configuration fields (see ``docs/protocol.md``); others keep their values."""
        self._send(codec.control_record(self._next(), software_trigger=software_trigger, **config))
        if "bit_depth" in config:
            self._depth = config["bit_depth"]

    def sequence_frames(self):
        """The most frames a stored sequence holds on this projector: every whole frame of its
        DMD in the store's memory (170 XGA frames), up to the slots an entry record names (256)."""
        status = self.status()
        return records.sequence_frames(status["dmd_rows"], status["dmd_columns"])

    def play_sequence(self, images, entries, *, loop=True, depth=None, tolerance=0.5):
        """Store ``images`` as a sequence (frame ``k`` in slot ``k``) and play it by an entry
        table: ``entries``, each a dict of :func:`host.codec.entry_record`'s settings with its
        ``slot`` (``lsb``, ``dark``, ``follow``, ``camera``, ``depth``, ``skip``; see
        ``docs/protocol.md``), in a loop or once. The table and the control record that plays it
        go first, then the frames, so that the projector gives out nothing before both are in;
        each frame is checked as :meth:`send_image` checks it. An entry the projector would drop,
        or skip when it plays (planes its frame is not sent with: each frame goes at the depth
        :meth:`send_image` chooses), is refused before anything is sent. Returns the
        :class:`Sent` of each image."""
        # (the images have the DMD's geometry, as each send checks: nothing to ask the projector)
        held = records.sequence_frames(*np.shape(images[0])) if len(images) else 0
        if not 2 <= len(images) <= held:
            raise ClientError(f"a stored sequence holds 2 to {held} frames of this DMD, not {len(images)}")
        if not 1 <= len(entries) <= records.ENTRIES:
            raise ClientError(f"an entry table holds 1 to {records.ENTRIES} entries, not {len(entries)}")
        outside = [e["slot"] for e in entries if not 0 <= e["slot"] < len(images)]
        if outside:
            raise ClientError(f"entries name slots {outside} outside the sequence of {len(images)} frames")
        settings = [{k: v for k, v in entry.items() if k != "slot"} for entry in entries]
        depths = [levels.quantise(image, depth, tolerance=tolerance).depth for image in images]
        for index, (entry, extra) in enumerate(zip(entries, settings, strict=True)):
            try:            # checked before anything is sent
                codec.entry_record(index, entry["slot"], **extra)
            except ValueError as error:
                raise ClientError(f"entry {index}: {error}") from None
            missing = _planes_missing(extra.get("depth", 0), extra.get("skip", 0), depths[entry["slot"]])
            if missing:
                raise ClientError(f"entry {index}: {missing}; the projector would skip it")
        self.control(sequence_length=len(images))
        for index, (entry, extra) in enumerate(zip(entries, settings, strict=True)):
            self._send(codec.entry_record(index, entry["slot"], self._next(), **extra))
        self._send(codec.control_record(self._next(), entries=len(entries), loop=int(loop), sequence_start=True))
        return [self.send_image(image, k, depth=depth, tolerance=tolerance) for k, image in enumerate(images)]

    def configure(self, plan, dmd):
        """Send the register set of a :func:`spec.schedule.plan` (checked as the
        projector checks it, and a periodic trigger against the plan's frame period:
        :func:`period_fault`); the sequencer takes it when no frame is playing."""
        fault = period_fault(plan)
        if fault:
            raise ClientError(fault)
        self._send(codec.sequencer_record(plan.params.registers(dmd), self._next(), dmd=dmd,
                                          beats=plan.params.beats))


class MasterClient(_Link):
    """Talks to the sync master of a tiled display (``docs/protocol.md``, Master control record).

    Parameters
    ----------
    address : str
        The master's IPv4 address.
    port : int
        Its UDP port.
    timeout : float
        Seconds to wait for a status reply.
    rate, mtu, bind
        As :class:`Client`'s (a master's records are short: they hardly matter).
    """

    _REPLY = RecordType.MASTER_STATUS

    def configure(self, *, mode=None, armed=None, period_s=None, min_period_s=None, width_s=None):
        """Set the given settings (the others keep their values) in one master control record.

        Times are in seconds, sent as whole cycles of the master's clock (``clock_hz`` from a
        status reply read first, rounded to the nearest). The configuration the record would
        leave in force is checked as the master checks it
        (:func:`spec.records.master_config_faults`, and each value against its field's width);
        one it would drop raises :class:`ClientError` naming the failed checks, before anything
        is sent.

        Parameters
        ----------
        mode : spec.registers.TriggerMode or int, optional
            What starts a frame: EXTERNAL (the trigger pin), PERIODIC or SOFTWARE (:meth:`trigger`).
        armed : bool, optional
            Triggers are obeyed only while armed.
        period_s, min_period_s, width_s : float, optional
            The periodic trigger's period; the shortest time from one pulse to the next trigger
            obeyed (the frame period every board keeps); each sync and camera pulse's length.

        Returns
        -------
        dict
            The configuration now in force (:data:`spec.records.MASTER_CONFIG`'s fields, in cycles).
        """
        status = self.status()
        fields = {name: int(value) for name, value in (("mode", mode), ("armed", armed)) if value is not None}
        fields |= {name: round(seconds * status["clock_hz"])
                   for name, seconds in (("period", period_s), ("min_period", min_period_s), ("width", width_s))
                   if seconds is not None}
        widths = dict(records.MASTER_CONFIG)
        merged = {name: fields.get(name, status[name]) for name in widths}
        faults = records.master_config_faults(merged)
        # a value wider than its field does not go on the wire at all: a failed check as well
        faults |= {f"{name}_fits": True for name, value in fields.items() if not 0 <= value < 1 << widths[name]}
        failed = [check for check, bad in faults.items() if bad]
        if failed:
            now = ", ".join(f"{name} {value}" for name, value in merged.items())
            raise ClientError(f"the sync master cannot take this configuration ({now}; times in cycles of "
                              f"{status['clock_hz']} Hz): {', '.join(failed)}")
        self._send(codec.master_control_record(self._next(), **fields))
        return merged

    def trigger(self):
        """Fire one software trigger (a master control record setting nothing). The master obeys
        it only in mode SOFTWARE, armed, with every board ready and ``min_period`` passed since
        its last pulse; its status counts what it refused (``not_ready``, ``early``)."""
        self._send(codec.master_control_record(self._next(), software_trigger=True))
