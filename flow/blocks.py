"""The blocks that ship, each as a standalone top for the resource report and the ISE tree.

One entry per block: ``name -> factory``. The factory builds the block with the geometry and
parameters it ships with. ``make resources`` synthesises each for XC6SLX45 and reports it as
``res.<name>.*``; ``make verilog`` writes each block's Verilog beside the platform top.
"""

from spec.facts import DMDS

#: Build-time addresses of the Ethernet blocks; a control record may change them at run time.
_ADDRESSES = {"mac": 0x02_00_00_00_00_01, "ip": 0xC0_A8_01_0A, "port": 5000}


def _serialiser():
    from gateware.bitplane import Serialiser
    return Serialiser(DMDS["dlp7000"], lanes=8)


def _receive_path():
    from gateware.mac.path import ReceivePath
    return ReceivePath()


def _transmit_path():
    from gateware.mac.path import TransmitPath
    return TransmitPath()


def _endpoint():
    from gateware.protocol.endpoint import Endpoint
    return Endpoint(DMDS["dlp7000"], **_ADDRESSES)


def _ethernet_port():
    from gateware.protocol.port import EthernetPort
    # The whole Ethernet side: receive MAC, stack and protocol, transmit MAC.
    return EthernetPort(_endpoint())


def _xga_slots():
    """The projector's frame slots for the DLP7000 (every XGA frame the DDR2 holds)."""
    from gateware.top.system import slots_for
    return slots_for(DMDS["dlp7000"])


def _frame_slots():
    from gateware.store.slots import FrameSlots
    return FrameSlots(DMDS["dlp7000"], slots=_xga_slots())


def _writer():
    from gateware.store.writer import Writer
    return Writer(DMDS["dlp7000"], slots=_xga_slots())


def _reader():
    from gateware.store.reader import Reader
    return Reader(DMDS["dlp7000"], slots=_xga_slots())


def _read_widener():
    from gateware.platform.read_widener import ReadWidener
    return ReadWidener()


def _sequencer(dmd="dlp7000"):
    from gateware.dlpc410.sequencer import Sequencer
    return Sequencer(DMDS[dmd])


def _register_crossing():
    from gateware.dlpc410.register_crossing import RegisterCrossing
    from spec import schedule
    # The sequencer's register sets from the protocol (sync) into dmd, power-up value as the
    # platform's.
    dmd = DMDS["dlp7000"]
    return RegisterCrossing(schedule.plan(dmd, 200e6).params.registers(dmd))


def _sync_master():
    from gateware.sync.master import SyncMaster
    from gateware.top.sync_master import BOARDS
    return SyncMaster(BOARDS)


def _sync_master_core():
    """The sync master behind its network port, as its board builds it."""
    from gateware.top.sync_master import board_core
    return board_core()


def _clock_trim():
    from gateware.sync.clock_trim import ClockTrim
    return ClockTrim()


def _trim_dac():
    from gateware.sync.trim_dac import TrimDac
    from spec.schedule import FABRIC_HZ
    return TrimDac(FABRIC_HZ)


#: Each block under one name: its class's, in snake case (``res.<name>.*``, ``blocks/<name>.v``).
BLOCKS = {
    "receive_path": _receive_path,
    "transmit_path": _transmit_path,
    "endpoint": _endpoint,
    "ethernet_port": _ethernet_port,
    "serialiser": _serialiser,
    "frame_slots": _frame_slots,
    "writer": _writer,
    "reader": _reader,
    "read_widener": _read_widener,
    "sequencer": _sequencer,
    "sequencer_dlp9500": lambda: _sequencer("dlp9500"),
    "register_crossing": _register_crossing,
    "sync_master": _sync_master,
    "sync_master_core": _sync_master_core,
    "clock_trim": _clock_trim,
    "trim_dac": _trim_dac,
}


def core(dmd="dlp7000", dclk_hz=400e6):
    """The projector's core as the board builds it (:func:`gateware.top.platform.core`)."""
    from gateware.top.platform import core as board_core
    return board_core(DMDS[dmd], dclk_hz)
