"""The MCB port model: it moves data with the timing it promises, and catches every rule a
client can break (each violation injected once)."""

import pytest

from sim.models.mcb_model import READ, REFRESH, WRITE, WRITE_PRECHARGE, McbError, McbModel, McbTiming
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


def test_ports_of_other_widths_share_the_memory():
    """64-bit words written on one port read back as 128-bit words on another, the first in the
    low bits, and 32-bit words as halves; 128-bit words written with byte masks read back as
    64-bit words with the masked bytes unchanged (numbers worked out by hand from the byte
    order)."""
    model = McbModel(1 << 16, ports=3, widths=(64, 128, 32))
    drivers = narrow, wide, half = [PortDriver(model, i) for i in range(3)]

    def on(driver):
        """``driver``, its clock brought to the others' time (one clock for all three)."""
        driver.cycle = max(d.cycle for d in drivers)
        return driver

    for port in drivers:
        on(port).until_calibrated()
    words = [0x1111111111111111 * (i + 1) for i in range(8)]
    on(narrow).write(0x100, words)
    assert on(wide).read(0x100, 4) == [words[i] | words[i + 1] << 64 for i in range(0, 8, 2)]
    assert on(half).read(0x108, 2) == [0x2222_2222, 0x2222_2222]
    on(wide).write(0x200, [0xAAAA_AAAA_AAAA_AAAA_BBBB_BBBB_BBBB_BBBB], masks=[0x80FF])   # keep bytes 0-7, 15
    assert on(narrow).read(0x200, 2) == [0, 0x00AA_AAAA_AAAA_AAAA]
    on(wide).write(0x200, [0x0102_0304_0506_0708_090A_0B0C_0D0E_0F10], masks=[0xFEFF])   # byte 8 only
    assert on(narrow).read(0x200, 2) == [0, 0x00AA_AAAA_AAAA_AA08]
    with pytest.raises(McbError) as error:                  # 8-byte aligned, not 16
        wide.tick(cmd_en=1, cmd_instr=READ, cmd_bl=0, cmd_byte_addr=0x108)
    assert error.value.kind == "misaligned"


def test_a_wide_word_takes_its_bytes_of_memory_time():
    """The DRAM sets the bandwidth: 128-bit words move at half the word rate of 64-bit ones,
    the same bytes per second (within refresh and latency)."""
    def rate(width):
        model = McbModel(1 << 20, widths=(width,), ports=1)
        clk = PortDriver(model, period=5e-9)
        clk.until_calibrated()
        start = clk.cycle
        clk.read(0, 64 * 64 * 64 // width)              # 32 KiB
        return 32768 / ((clk.cycle - start) * 5e-9)

    narrow, wide = rate(64), rate(128)
    assert wide == pytest.approx(narrow, rel=0.02)
    assert wide < McbTiming().peak_bytes_per_s * McbTiming().efficiency


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



LOSS_AT, LOSS_S = 5e-6, 2e-6


def lost_and_regained(**model_args):
    """A port that wrote 8 words at 0x100, then lost the calibration at ``LOSS_AT`` with a word
    in its write FIFO and a read under way (words in the read FIFO and on their way), and waited
    until calibrated again; its FIFOs stay empty meanwhile."""
    model = McbModel(1 << 16, timing=McbTiming(calib_lost_at_s=LOSS_AT, calib_lost_s=LOSS_S), **model_args)
    clk = PortDriver(model)
    clk.until_calibrated()
    data = [0x0123456789ABCDEF * (i + 1) & (2**64 - 1) for i in range(8)]
    clk.write(0x100, data)
    assert clk.read(0x100, 8) == data                   # before the loss, as always
    while (clk.cycle + 20) * clk.period < LOSS_AT:
        clk.tick()
    clk.tick(cmd_en=1, cmd_instr=READ, cmd_bl=63, cmd_byte_addr=0x400)
    clk.tick(wr_en=1, wr_data=1)
    while clk.port.outputs["calib_done"]:
        before = clk.port.outputs
        clk.tick()
    assert before["wr_count"] == 1 and before["rd_count"] > 0
    lost = clk.cycle
    assert model.calib_losses == 1
    while not clk.port.outputs["calib_done"]:
        out = clk.tick()
        for name, value in dict(cmd_empty=1, wr_empty=1, wr_count=0, rd_empty=1, rd_count=0).items():
            assert out[name] == value, name
    assert (clk.cycle - lost) * clk.period == pytest.approx(LOSS_S, abs=clk.period)
    return model, clk, data


def test_calibration_lost_and_regained():
    """The port is reset (FIFOs empty, the read under way gone for good), the memory garbage."""
    model, clk, _data = lost_and_regained()
    for _ in range(200):                                # nothing of the lost read arrives
        assert clk.tick()["rd_empty"]
    assert int(model.memory[0x100 // 8]) == 0xDEAD_0000_0000_0000 | 0x100 // 8
    assert model.calib_losses == 1


def test_read_of_a_word_lost_with_the_calibration():
    _model, clk, _data = lost_and_regained()
    with pytest.raises(McbError) as error:
        clk.read(0x100, 1)
    assert error.value.kind == "read_lost"


def rewritten():
    """After the loss: 0x100 written again on a 64-bit port, the low half of 0x200 on a 32-bit
    one, the high half of 0x300 with a masked 64-bit write."""
    model, wide, data = lost_and_regained(ports=2, widths=(64, 32))
    half = PortDriver(model, 1)
    wide.write(0x100, data[::-1])
    assert wide.read(0x100, 8) == data[::-1]
    half.cycle = wide.cycle
    half.write(0x200, [0x1234_5678])
    assert half.read(0x200, 1) == [0x1234_5678]
    wide.cycle = half.cycle
    wide.write(0x300, [0x0123_4567_89AB_CDEF], masks=[0x0F])     # bytes 4-7 only
    half.cycle = wide.cycle
    assert half.read(0x304, 1) == [0x0123_4567]
    return wide, half


def test_words_written_again_after_the_loss():
    rewritten()


@pytest.mark.parametrize("port, address", [(1, 0x204), (0, 0x200), (0, 0x300)])
def test_words_written_in_part_after_the_loss(port, address):
    """The bytes not written since the loss are still lost."""
    drivers = rewritten()
    driver = drivers[port]
    driver.cycle = max(d.cycle for d in drivers)
    with pytest.raises(McbError) as error:
        driver.read(address, 1)
    assert error.value.kind == "read_lost"


def test_traffic_during_the_calibration_loss():
    def action(clk):
        while clk.cycle * clk.period < LOSS_AT + 1e-7:
            clk.tick()
        assert not clk.port.outputs["calib_done"]
        clk.tick(cmd_en=1, cmd_instr=READ, cmd_bl=0, cmd_byte_addr=0)
    violation("before_calib", action, timing=McbTiming(calib_lost_at_s=LOSS_AT, calib_lost_s=LOSS_S))


def test_no_calibration_loss_by_default():
    model = McbModel(1 << 16)
    clk = PortDriver(model)
    clk.until_calibrated()
    for _ in range(2000):
        assert clk.tick()["calib_done"]
    assert clk.read(0x100, 4) == [0] * 4               # never written, not lost: legal
    assert model.calib_losses == 0 and model.lost is None
