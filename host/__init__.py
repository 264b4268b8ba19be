"""Host side of the projector's network protocol: record encoder/decoder, UDP clients (the
projector's, a tiled display's sync master's) and CLI.

The records are built from :mod:`spec.records`, the same tables the gateware parser
is generated from; the testbenches feed the gateware with this very encoder. Plain Python and
numpy: no HDL toolchain.
"""

from .client import Client, ClientError, MasterClient, Sent
from .codec import (
                      ProtocolError,
                      changed_rows,
                      control_record,
                      decode,
                      image_record,
                      image_records,
                      master_control_record,
                      pixels_per_record,
                      sequence_records,
                      sequencer_record,
                      status_query,
)
from .levels import Quantised, quantise

__all__ = ["Client", "ClientError", "MasterClient", "ProtocolError", "Quantised", "Sent", "changed_rows",
           "control_record", "decode", "image_record", "image_records", "master_control_record", "pixels_per_record",
           "quantise", "sequence_records", "sequencer_record", "status_query"]
