"""Run-time parameters of the DLPC410 sequencer: the modes and the one register struct.

Every duration is a cycle count of the ``dmd`` domain, set at run time (by the control block from
a host record); nothing in the gateware bakes in a frame rate, an exposure or a TI timing number.
The host computes a consistent set with :mod:`gateware.dlpc410.schedule` (:func:`plan`), which
also says which constraint binds.
"""

from amaranth.lib import data, enum

__all__ = ["ResetMode", "PlaneOrder", "TriggerMode", "Source", "Registers",
           "TIME_BITS", "LSB_BITS", "DURATION_BITS", "group_size"]

#: Width of the free-running time base. Comparisons are made on differences, so the base may
#: wrap (every 8 days at 400 MHz) without harm; every wait is shorter than 2**(TIME_BITS-1).
TIME_BITS = 48
#: Width of the least significant plane's duration: up to 2**32 cycles (10.7 s at 400 MHz).
LSB_BITS = 32
#: Width of any plane duration (LSB shifted by up to 7) and of the other long waits.
DURATION_BITS = LSB_BITS + 8


class ResetMode(enum.Enum, shape=2):
    """Which blocks one mirror clocking pulse covers (DLPC410 block commands)."""
    GLOBAL = 0   # all blocks together (BLKMD=11, BLKAD=10xx)
    QUAD = 1     # blocks 4q..4q+3, phased (BLKMD=11, BLKAD=0qq0, RST2BLKZ=1)
    DUAL = 2     # blocks 2p, 2p+1, phased (BLKMD=11, BLKAD=0ppp, RST2BLKZ=0)
    SINGLE = 3   # one block, phased (BLKMD=10)


class PlaneOrder(enum.Enum, shape=2):
    """Display order of a frame's planes."""
    MSB_FIRST = 0
    LSB_FIRST = 1
    TABLE = 2    # ``order_table[j]`` = weight exponent (0 = least significant) shown j-th


class TriggerMode(enum.Enum, shape=2):
    """What starts a frame."""
    EXTERNAL = 0   # rising edge of the TTL trigger input
    PERIODIC = 1   # free-running, every ``period`` cycles
    SOFTWARE = 2   # a pulse on the ``soft_trigger`` port (a control record)
    SYNC = 3       # rising edge of the sync input: tiled projectors start their first plane
                   # together (MSB_FIRST: the most significant plane on every board at once)


class Source(enum.Enum, shape=1):
    """Where row data comes from."""
    STORE = 0      # planes read from the frame store
    PRNG = 1       # on-chip Bernoulli(1/2) patterns, 1-bit frames, no memory bandwidth


def group_size(mode, blocks):
    """Blocks per clocking-pulse group for a reset mode."""
    return {ResetMode.GLOBAL: blocks, ResetMode.QUAD: 4, ResetMode.DUAL: 2,
            ResetMode.SINGLE: 1}[ResetMode(mode)]


class Registers(data.Struct):
    """The sequencer's run-time parameters (all durations in ``dmd`` cycles).

    Fields
    ------
    reset_mode, order, order_table
        Pulse grouping; plane order (``order_table`` used with :attr:`PlaneOrder.TABLE`).
    chain
        Frames follow one another without a trigger once the first trigger started them
        (binary pattern mode, continuous PWM); otherwise every frame waits for its trigger.
    strict_rst
        1: no pulse of any group while RST_ACTIVE may be high from any pulse (the strict
        reading); 0: only pulses of the same group wait for each other.
    trigger, source
        Trigger mode; row-data source.
    lsb
        Duration of the least significant plane (even). Plane of weight 2**e lasts ``lsb << e``.
    t_rst, t_settle
        RST_ACTIVE time and mirror settle time after it: a pulsed group's memory changes no
        sooner than ``t_rst + t_settle`` after its pulse.
    hide
        A plane at least this long has the next plane loaded behind it; shorter planes are
        ended by a dark pulse of cleared blocks.
    dark_gap
        From a dark pulse to the next plane's pulse (covers settle and the reload).
    stagger
        Cycles between the pulses of consecutive groups (phased modes); even.
    row_period
        Cycles from one row load to the next (at least DCLK-per-row; sets the memory bandwidth).
    reload_lead
        A frame taken while every group waits for a trigger has its first plane loaded no sooner
        than this many cycles later: the requester's occupancy look-up plus the store's latency
        to the first words of a row (set it from the store's measured read latency).
    period
        Trigger period of :attr:`TriggerMode.PERIODIC`.
    camera_offset, camera_width
        Camera-trigger pulse: starts this many cycles after a frame's first pulse, this long.
    ns_flip, park
        NS_FLIP pin; PWR_FLOAT (park the mirrors).
    """
    reset_mode: ResetMode
    order: PlaneOrder
    order_table: data.ArrayLayout(3, 8)
    chain: 1
    strict_rst: 1
    trigger: TriggerMode
    source: Source
    lsb: LSB_BITS
    t_rst: 16
    t_settle: 16
    hide: DURATION_BITS
    dark_gap: DURATION_BITS
    stagger: 24
    row_period: 8
    reload_lead: 16
    period: DURATION_BITS
    camera_offset: DURATION_BITS
    camera_width: 16
    ns_flip: 1
    park: 1
