"""Reference model of a sync master's network endpoint (:class:`gateware.protocol.master.MasterEndpoint`).

The network stack's rules are :class:`sim.models.net_model.Model`'s; the records' are written here
from ``docs/protocol.md`` (master control record, status query), not from the gateware's parser:
what each record does to the configuration, the software triggers it fires, and every counter
the master status reply carries.
"""

from dataclasses import dataclass, field

from spec import records, wire
from spec.records import RecordType
from spec.registers import TriggerMode

from .net_model import Model

__all__ = ["MasterModel"]

_HEADER = wire.size(records.HEADER)
_SIZES = {RecordType.MASTER_CONTROL: _HEADER + wire.size(records.MASTER_CONTROL),
          RecordType.STATUS_QUERY: _HEADER}


@dataclass
class MasterModel(Model):
    """The master's endpoint, fed frame by frame (:meth:`frame`); ``dmd`` None (a master has none).

    Attributes
    ----------
    master : dict
        The configuration in force (:data:`spec.records.MASTER_CONFIG`'s names).
    triggers : int
        Software triggers the records fired.
    """
    master: dict = field(default_factory=dict)

    def __post_init__(self):
        for name, _ in records.NET_COUNTERS + records.MASTER_RECORD_COUNTERS:
            self.counters.setdefault(name, 0)
        self.config = {"mac": self.mac, "ip": self.ip, "port": self.port}

    def _record(self, data, peer):
        head = wire.unpack(records.HEADER, data + bytes(max(0, _HEADER - len(data))))
        kind = head["type"]
        if head["magic"] != records.MAGIC:
            return "drop_app_magic"
        if head["version"] != records.VERSION:
            return "drop_app_version"
        if kind not in _SIZES:
            return "drop_app_type"
        if len(data) != _SIZES[kind]:
            return "drop_app_length"
        if kind == RecordType.MASTER_CONTROL:
            body = wire.unpack(records.MASTER_CONTROL, data[_HEADER:])
            names = [name for name, _ in records.MASTER_CONFIG]
            after = {name: body[name] if body["apply"] >> i & 1 else self.master[name]
                     for i, name in enumerate(names)}
            # the protocol page's rules: a mode the master obeys, armed 0 or 1, each pulse ends
            # before the next may start, a period the boards keep
            if (after["mode"] not in (TriggerMode.EXTERNAL, TriggerMode.PERIODIC, TriggerMode.SOFTWARE)
                    or after["armed"] > 1 or not 1 <= after["width"] < after["min_period"]
                    or (after["mode"] == TriggerMode.PERIODIC and after["period"] < after["min_period"])):
                return "drop_app_value"
        mask = (1 << dict(records.HEADER)["sequence"]) - 1
        if self._sequence is not None and head["sequence"] != (self._sequence + 1) & mask:
            self.count("sequence_gaps")
        self._sequence = head["sequence"]
        if kind == RecordType.MASTER_CONTROL:
            self.master = after
            self.triggers += body["action"] & 1
            self.count("records_control")
            return "control"
        self.count("records_status")
        self.replies.append(("status", {**(peer or {}), "sequence": head["sequence"]}))
        return "status"
