"""A UDP client for the projector: sends images and control records, asks for status."""

import socket
import time

from spec.records import RecordType

from . import codec

__all__ = ["Client", "ClientError", "DEFAULT_PORT"]

DEFAULT_PORT = 5000


class ClientError(RuntimeError):
    """The projector did not answer, or answered with something we cannot use."""


class Client:
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
    """

    def __init__(self, address, port=DEFAULT_PORT, *, timeout=1.0, rate=None, bind=("0.0.0.0", 0)):
        self.peer = (address, port)
        self.timeout = timeout
        self.rate = rate
        self.sequence = 0
        self._sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self._sock.bind(bind)
        self._sock.settimeout(timeout)
        self._paced_since = None
        self._paced_bytes = 0

    def close(self):
        self._sock.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def _next(self):
        sequence = self.sequence
        self.sequence = (self.sequence + 1) & 0xFFFFFFFF
        return sequence

    def _send(self, record):
        if self.rate:
            now = time.monotonic()
            if self._paced_since is None:
                self._paced_since = now
            ahead = self._paced_since + self._paced_bytes / self.rate - now
            if ahead > 0:
                time.sleep(ahead)
            elif ahead < -0.1:
                # idle for a while: do not burst to catch up
                self._paced_since, self._paced_bytes = now, 0
            self._paced_bytes += len(record)
        try:
            self._sock.sendto(record, self.peer)
        except OSError as error:
            raise ClientError(f"cannot send to {self.peer[0]}:{self.peer[1]}: {error}") from error

    def send_records(self, encoded):
        """Send already encoded records (their sequence numbers are kept)."""
        for record in encoded:
            self._send(record)
        return len(encoded)

    def send_image(self, image, frame=0):
        """Send one ``uint8`` image as frame ``frame``; returns the records sent."""
        encoded = codec.image_records(image, frame, sequence=self.sequence)
        self.sequence = (self.sequence + len(encoded)) & 0xFFFFFFFF
        return self.send_records(encoded)

    def send_sequence(self, images, first_frame=0):
        encoded = codec.sequence_records(images, first_frame, sequence=self.sequence)
        self.sequence = (self.sequence + len(encoded)) & 0xFFFFFFFF
        return self.send_records(encoded)

    def control(self, *, software_trigger=False, **config):
        """Set configuration fields (see ``docs/protocol.md``); others keep their values."""
        self._send(codec.control_record(self._next(), software_trigger=software_trigger, **config))

    def configure(self, plan, dmd):
        """Send the register set of a :func:`spec.schedule.plan` (checked as the
        projector checks it); the sequencer takes it when no frame is playing."""
        self._send(codec.sequencer_record(plan.params.registers(dmd), self._next(), dmd=dmd,
                                          beats=plan.params.beats))

    def status(self, retries=2):
        """Ask for a status reply and return its fields as a dict."""
        for _attempt in range(retries + 1):
            sequence = self._next()
            self._send(codec.status_query(sequence))
            deadline = time.monotonic() + self.timeout
            while (left := deadline - time.monotonic()) > 0:
                self._sock.settimeout(left)
                try:
                    raw, sender = self._sock.recvfrom(65536)
                except socket.timeout:
                    break
                except OSError as error:
                    raise ClientError(f"no status from {self.peer[0]}:{self.peer[1]}: {error}") \
                        from error
                if sender != self.peer:
                    continue
                try:
                    head, body, _rest = codec.decode(raw)
                except codec.ProtocolError as error:
                    raise ClientError(f"bad status reply from {sender[0]}:{sender[1]}: {error}") \
                        from error
                if head["type"] == RecordType.STATUS_REPLY and head["sequence"] == sequence:
                    return body
        raise ClientError(f"no status reply from {self.peer[0]}:{self.peer[1]} "
                          f"after {retries + 1} tries of {self.timeout} s")
