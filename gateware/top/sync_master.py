"""The sync master's own build: :class:`~gateware.sync.master.SyncMaster` on the Atlys.

A tiled display's main control board. Its pins sit on the Atlys's VHDCI connector (LVCMOS33, a
bank the board's jumper sets to 3.3 V): one sync line and one ready line per projector board, the
frame trigger in and the camera trigger out. Every output leaves from a flip-flop in its pad
(``io.FFBuffer``, packed into the IOB by ISE), so that the sync pulses to the boards differ only by
the pads' and the cables' skew. The ``sync`` domain is the board's 100 MHz oscillator.

The frame timing is the build's (a lab rebuilds for another frame rate): the trigger period,
the shortest frame period the boards keep and the pulse width, in seconds. The switches choose
what starts a frame and arm it; button 0 is the software trigger (the host's trigger record on a
build with a network port). The LEDs show the boards' ready lines, and each refusal for a board
not ready or for a trigger too early toggles its LED.
"""

from amaranth import Cat, Elaboratable, Module, Signal
from amaranth.build import Attrs, Pins, Resource
from amaranth.lib import io
from amaranth.lib.cdc import FFSynchronizer
from amaranth_boards.atlys import AtlysPlatform

from gateware.registers import TriggerMode
from gateware.sync.master import SyncMaster

__all__ = ["SyncMasterPlatform", "SyncMasterTop", "sync_master_resources", "BOARDS", "SYNC_HZ"]

#: Projector boards the build drives (the four-DMD projector).
BOARDS = 4
#: The ``sync`` domain: the Atlys's oscillator.
SYNC_HZ = 100e6
#: VHDCI pins (single-ended) for each board's sync line and ready line, the trigger and the camera.
_SYNC_PINS = ("1", "3", "4", "6")
_READY_PINS = ("35", "37", "38", "40")
_TRIGGER_PIN, _CAMERA_PIN = "7", "41"


def sync_master_resources(boards=BOARDS):
    """The sync master's pins on the VHDCI connector: fast 12 mA outputs (cables to the boards)."""
    out = Attrs(IOSTANDARD="LVCMOS33", SLEW="FAST", DRIVE="12")
    inp = Attrs(IOSTANDARD="LVCMOS33")
    return [
        *[Resource("board_sync", k, Pins(_SYNC_PINS[k], dir="o", conn=("vhdci", 0)), out) for k in range(boards)],
        *[Resource("board_ready", k, Pins(_READY_PINS[k], dir="i", conn=("vhdci", 0)), inp) for k in range(boards)],
        Resource("frame_trigger_in", 0, Pins(_TRIGGER_PIN, dir="i", conn=("vhdci", 0)), inp),
        Resource("camera_trigger_out", 0, Pins(_CAMERA_PIN, dir="o", conn=("vhdci", 0)), out),
    ]


class SyncMasterPlatform(AtlysPlatform):
    """The Atlys with the sync master's pins."""
    resources = AtlysPlatform.resources + sync_master_resources()


class SyncMasterTop(Elaboratable):
    """The sync master for :class:`SyncMasterPlatform`.

    Parameters
    ----------
    boards : int
    period_s, min_period_s, width_s : float
        The periodic trigger's period, the shortest frame period the boards keep (a trigger
        sooner after the last pulse is refused), and each pulse's width.

    Switches: 0-1 the trigger mode (:class:`~gateware.registers.TriggerMode`: 0 the pin, 1 the
    period, 2 software, button 0; 3, the sync input, has no source here and obeys nothing), 7 arms. LEDs: 0-3 the boards
    ready, 4 toggles at each pulse, 5 at each refusal for a board not ready, 6 for one too early.
    """

    def __init__(self, boards=BOARDS, *, period_s=1 / 400, min_period_s=1 / 460, width_s=1e-6):
        assert boards <= len(_SYNC_PINS)
        self._boards = boards
        self._period, self._min_period, self._width = (round(t * SYNC_HZ) for t in (period_s, min_period_s, width_s))

    def elaborate(self, platform):
        m = Module()
        boards = self._boards
        m.submodules.master = master = SyncMaster(boards)
        m.d.comb += [master.period.eq(self._period), master.min_period.eq(self._min_period),
                     master.width.eq(self._width)]

        # the outputs from flip-flops in their pads
        for k in range(boards):
            m.submodules[f"sync{k}"] = pad = io.FFBuffer("o", platform.request("board_sync", k, dir="-"))
            m.d.comb += pad.o.eq(master.sync_out[k])
        m.submodules.camera = camera = io.FFBuffer("o", platform.request("camera_trigger_out", 0, dir="-"))
        m.d.comb += camera.o.eq(master.camera_out)
        def pins(direction, name, count):
            """Resource ``name`` 0..count-1 through plain buffers: their values, or their drives."""
            values = []
            for k in range(count):
                m.submodules[f"{name}_{k}"] = buffer = io.Buffer(direction, platform.request(name, k, dir="-"))
                values.append(buffer.i if direction == "i" else buffer.o)
            return Cat(values)

        # the inputs are asynchronous: the master synchronises them
        ready = pins("i", "board_ready", boards)
        m.d.comb += [master.ready.eq(ready), master.trigger_in.eq(pins("i", "frame_trigger_in", 1))]

        # switches and buttons: synchronised; the button's rising edge is one software trigger
        switches = Signal(8)
        m.submodules.switches = FFSynchronizer(pins("i", "switch", 8), switches)
        button, was = Signal(), Signal()
        m.submodules.button = FFSynchronizer(pins("i", "button", 1), button)
        m.d.sync += was.eq(button)
        m.d.comb += [master.mode.eq(TriggerMode(switches[0:2])), master.run.eq(switches[7]),
                     master.soft.eq(button & ~was)]

        # LEDs: the ready lines, and a toggle per pulse and per refusal
        leds = pins("o", "led", 8)
        toggles = Signal(3)
        for bit, counter in enumerate((master.pulses, master.not_ready, master.early)):
            m.d.comb += toggles[bit].eq(counter[0])
        m.d.comb += leds.eq(Cat(ready, toggles))
        return m
