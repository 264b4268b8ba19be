"""Host side of the projector's network protocol: record encoder/decoder, UDP client and CLI.

The records are built from :mod:`spec.records`, the same tables the gateware parser
is generated from; the testbenches feed the gateware with this very encoder.
"""

from .client import Client, ClientError
from .codec import (
                      ProtocolError,
                      control_record,
                      decode,
                      image_records,
                      rows_per_record,
                      sequence_records,
                      sequencer_record,
                      status_query,
)

__all__ = ["Client", "ClientError", "ProtocolError", "control_record", "decode", "image_records",
           "rows_per_record", "sequence_records", "sequencer_record", "status_query"]
