"""The blocks that ship, each as a standalone top for the resource report and the ISE tree.

One entry per block: ``name -> factory``. The factory builds the block with the geometry and
parameters it ships with. ``make resources`` synthesises each for XC6SLX45 and reports it as
``res.<name>.*``; ``make verilog`` writes each block's Verilog beside the platform top.
"""

from gateware.dlpc410.facts import DMDS


#: Build-time addresses of the Ethernet blocks; a control record may change them at run time.
_ADDRESSES = {"mac": 0x02_00_00_00_00_01, "ip": 0xC0_A8_01_0A, "port": 5000}


def _serialiser():
    from gateware.bitplane import Serialiser
    return Serialiser(DMDS["dlp7000"], lanes=8)


def _eth_rx():
    from gateware.mac.path import ReceivePath
    return ReceivePath()


def _eth_tx():
    from gateware.mac.path import TransmitPath
    return TransmitPath()


def _eth_stack():
    from gateware.net.ingest import Ingest
    return Ingest(DMDS["dlp7000"], **_ADDRESSES)


def _eth_port():
    from gateware.net.port import EthernetPort
    # The whole Ethernet side: receive MAC, stack and protocol, transmit MAC.
    return EthernetPort(DMDS["dlp7000"], **_ADDRESSES)


def _store_slots():
    from gateware.store.slots import FrameSlots
    return FrameSlots(DMDS["dlp7000"], slots=4)


def _store_writer():
    from gateware.store.writer import Writer
    return Writer(DMDS["dlp7000"], slots=4)


def _store_reader():
    from gateware.store.reader import Reader
    return Reader(DMDS["dlp7000"], slots=4)


def _seq(dmd="dlp7000"):
    from gateware.dlpc410.sequencer import Sequencer
    return Sequencer(DMDS[dmd])


def _seq_registers():
    from gateware.dlpc410 import schedule
    from gateware.top.control import RegisterCrossing
    # The sequencer's register sets from the protocol (sync) into dmd, power-up value as the
    # platform's.
    dmd = DMDS["dlp7000"]
    return RegisterCrossing(schedule.plan(dmd, 200e6).params.registers(dmd))


BLOCKS = {
    "serialiser": _serialiser,
    "eth_rx": _eth_rx,
    "eth_tx": _eth_tx,
    "eth_stack": _eth_stack,
    "eth_port": _eth_port,
    "store_slots": _store_slots,
    "store_writer": _store_writer,
    "store_reader": _store_reader,
    "seq": _seq,
    "seq_dlp9500": lambda: _seq("dlp9500"),
    "seq_registers": _seq_registers,
}
