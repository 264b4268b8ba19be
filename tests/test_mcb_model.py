"""The MCB port model: it moves data with the timing it promises, and catches every rule a
client can break (each violation injected once)."""

import pytest

from sim.models.mcb import READ, REFRESH, WRITE, WRITE_PRECHARGE, McbError, McbModel, McbTiming
from sim.models.store_stim import PortDriver


def write_burst(clk, address, words, instr=WRITE):
    for w in words:
        clk.tick(wr_en=1, wr_data=w)
    clk.tick(cmd_en=1, cmd_instr=instr, cmd_bl=len(words) - 1, cmd_byte_addr=address)


def read_burst(clk, address, count):
    clk.tick(cmd_en=1, cmd_instr=READ, cmd_bl=count - 1, cmd_byte_addr=address)
    got = []
    while len(got) < count:
        out = clk.port.outputs
        if not out["rd_empty"]:
            got.append(out["rd_data"])
            clk.tick(rd_en=1)
        else:
            clk.tick()
        assert clk.cycle < 10_000
    return got


def test_write_then_read_back():
    model = McbModel(1 << 16)
    clk = PortDriver(model)
    clk.until_calibrated()
    data = [(0x0123456789ABCDEF * (i + 1)) & (2**64 - 1) for i in range(64)]
    write_burst(clk, 0x100, data)
    assert read_burst(clk, 0x100, 64) == data
    write_burst(clk, 0x800, data[:1], instr=WRITE_PRECHARGE)
    assert read_burst(clk, 0x800, 1) == data[:1]
    assert model.ports[0].words_written == 65


def test_bandwidth_and_refresh():
    """A long stream of reads runs at the sustained rate; refreshes happen every 7.8 us."""
    timing = McbTiming()
    model = McbModel(1 << 20, timing=timing)
    clk = PortDriver(model, period=5e-9)
    clk.until_calibrated()
    start, words = clk.cycle, 0
    for n in range(60):
        words += len(read_burst(clk, (n * 64 * 8) % (1 << 19), 64))
    elapsed = (clk.cycle - start) * 5e-9
    rate = words * 8 / elapsed
    # one command at a time (no look-ahead here): the latency costs, but never more than the peak
    assert rate < timing.peak_bytes_per_s * timing.efficiency
    assert model.refreshes == pytest.approx(clk.cycle * 5e-9 / timing.refresh_interval_s, abs=1)


def test_user_refresh_instruction():
    model = McbModel(1 << 16)
    clk = PortDriver(model)
    clk.until_calibrated()
    clk.tick(cmd_en=1, cmd_instr=REFRESH)
    for _ in range(40):
        clk.tick()
    assert clk.port.outputs["cmd_empty"]


def violation(kind, action, **model_args):
    model = McbModel(1 << 16, **model_args)
    clk = PortDriver(model)
    with pytest.raises(McbError) as error:
        action(clk)
    assert error.value.kind == kind


def test_traffic_before_calibration():
    violation("before_calib", lambda clk: clk.tick(wr_en=1, wr_data=1))


def test_command_while_full():
    def action(clk):
        clk.until_calibrated()
        for _ in range(6):                  # reads of 64 words queue up behind each other
            clk.tick(cmd_en=1, cmd_instr=READ, cmd_bl=63, cmd_byte_addr=0)
    violation("cmd_full", action)


def test_misaligned_address():
    def action(clk):
        clk.until_calibrated()
        clk.tick(cmd_en=1, cmd_instr=READ, cmd_bl=0, cmd_byte_addr=0x104)
    violation("misaligned", action)


def test_burst_outside_memory():
    def action(clk):
        clk.until_calibrated()
        clk.tick(cmd_en=1, cmd_instr=READ, cmd_bl=63, cmd_byte_addr=(1 << 16) - 8)
    violation("out_of_range", action)


def test_write_command_before_its_data():
    def action(clk):
        clk.until_calibrated()
        for w in range(3):
            clk.tick(wr_en=1, wr_data=w)
        clk.tick(cmd_en=1, cmd_instr=WRITE, cmd_bl=3, cmd_byte_addr=0)    # 4 words, 3 there
    violation("data_missing", action)


def test_write_command_and_its_last_word_in_one_cycle():
    def action(clk):
        clk.until_calibrated()
        clk.tick(wr_en=1, wr_data=1)
        clk.tick(wr_en=1, wr_data=2, cmd_en=1, cmd_instr=WRITE, cmd_bl=1, cmd_byte_addr=0)
    violation("data_missing", action)


def test_write_underrun():
    """Without the push-time check (as the real MCB), the FIFO running dry is an underrun."""
    def action(clk):
        clk.until_calibrated()
        clk.tick(wr_en=1, wr_data=1)
        clk.tick(cmd_en=1, cmd_instr=WRITE, cmd_bl=7, cmd_byte_addr=0)
        for _ in range(100):
            clk.tick()
    violation("underrun", action, check_write_data=False)


def test_write_while_full():
    def action(clk):
        clk.until_calibrated()
        for w in range(65):
            clk.tick(wr_en=1, wr_data=w)
    violation("wr_full", action)


def test_read_overflow():
    def action(clk):
        clk.until_calibrated()
        clk.tick(cmd_en=1, cmd_instr=READ, cmd_bl=63, cmd_byte_addr=0)
        clk.tick(cmd_en=1, cmd_instr=READ, cmd_bl=0, cmd_byte_addr=0)   # word 65, never taken
        for _ in range(200):
            clk.tick()
    violation("overflow", action)


def test_read_while_empty():
    def action(clk):
        clk.until_calibrated()
        clk.tick(rd_en=1)
    violation("rd_empty", action)


def test_random_stalls_slow_it_down():
    """With random stalls the same reads take longer, and still arrive whole and in order."""
    def run(timing):
        model = McbModel(1 << 16, timing=timing, seed=5)
        clk = PortDriver(model, period=5e-9)
        clk.until_calibrated()
        model.memory[:64] = range(64)
        start = clk.cycle
        for _ in range(32):
            assert read_burst(clk, 0, 64) == list(range(64))
        return clk.cycle - start

    calm = run(McbTiming())
    stalled = run(McbTiming(stall_chance=0.5, stall_max_s=1e-6))
    assert stalled > calm * 1.5
