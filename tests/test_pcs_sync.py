"""Code-group alignment and receive synchronisation in the Amaranth simulator: every bit offset
aligned, and sync kept or lost on bit errors exactly as :class:`sim.models.pcs_model.Sync`
(figure 36-9, written apart) says."""

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from sim.models import pcs_model as model
from sim.models.pcs_stim import Chain, Line, group_of, run_cycles

IDLE = (0, 0, 0)


def idles(n):
    return model.transmit([IDLE] * n)


def with_errors(codes, errors):
    """``codes`` with bit ``bit`` of code-group ``index`` inverted, for each ``(index, bit)``."""
    codes = list(codes)
    for index, bit in errors:
        code = codes[index]
        codes[index] = code[:bit] + ("1" if code[bit] == "0" else "0") + code[bit + 1:]
    return codes


def model_sync(codes):
    """The model's ``sync_status`` after each code-group, and its count of losses."""
    sync, rd, out = model.Sync(), "-", []
    for code in codes:
        byte, control, code_error, disparity_error, rd = model.decode(code, rd)
        out.append(sync.step(byte, control, code_error or disparity_error))
    return out, sync.losses


def gateware_sync(codes, name):
    chain = Chain(sync=True)
    steps = [[(chain.decoder.code, model.to_int(c))] for c in codes] + [()]
    got = run_cycles(chain, steps, lambda ctx: (ctx.get(chain.sync.sync_status), ctx.get(chain.sync.losses)),
                     name=name)
    # the decoder's register; the synchroniser's state is a cycle behind its input
    return [bool(status) for status, _ in got[1:]], got[-1][1]


def check_sync(codes, name):
    want, losses = model_sync(codes)
    got, got_losses = gateware_sync(codes, name)
    assert got == want
    assert got_losses == losses
    return want, losses


def test_sync_is_acquired_on_the_third_comma(test_name):
    """Idles from the first code-group: in sync after the data code-group of the third /I/."""
    status, losses = check_sync(idles(40), test_name)
    assert status.index(True) == 5 and all(status[5:]) and losses == 0


@pytest.mark.parametrize("spacing, lost", [(1, True), (2, True), (4, True), (5, False), (9, False)])
def test_four_errors_lose_sync_unless_good_code_groups_come_between(spacing, lost, test_name):
    """Four code-group errors up to four apart lose sync; with four good code-groups between
    them (four in a row climb one step back) the link stays in sync. Bit ``a`` of a K28.5 or
    a D16.2 inverted is in no column."""
    errors = [(20 + spacing * i, 0) for i in range(4)]
    status, losses = check_sync(with_errors(idles(100), errors), test_name)
    assert (losses == 1) == lost
    assert status[-1]


def test_three_errors_keep_sync(test_name):
    """Three bad code-groups in a row take the machine to SYNC_ACQUIRED_4, still in sync."""
    status, losses = check_sync(with_errors(idles(60), [(20, 0), (21, 0), (22, 0)]), test_name)
    assert losses == 0 and all(status[5:])


@settings(max_examples=25, deadline=None)
@given(st.lists(st.tuples(st.integers(6, 79), st.integers(0, 9)), max_size=8))
def test_random_bit_errors_keep_or_lose_sync_as_the_model_says(errors):
    """Bit errors anywhere in a run of idles and a frame: ``sync_status`` each cycle, and the
    losses counted, as the model's state machine gives them."""
    frame = [(0, 0, 0)] * 8 + [(1, 0, 0x55)] * 7 + [(1, 0, 0xD5)] + [(1, 0, b) for b in range(40)]
    codes = model.transmit(frame + [IDLE] * 40)[:90]
    check_sync(with_errors(codes, errors), "pcs_random_bit_errors")


@pytest.mark.parametrize("slip", range(10))
def test_every_bit_offset_is_aligned_and_decoded(slip, test_name):
    """The line bits ``slip`` bits late: the aligner finds the comma, takes that offset, and
    every code-group after it decodes as sent."""
    data = [(1, 0, b) for b in range(0, 256, 7)]
    codes = model.transmit([IDLE] * 6 + [(1, 0, 0x55)] + data + [IDLE] * 10)
    chain = Chain(aligner=True)
    line = Line(slip)
    steps = [[(chain.aligner.bits, line.word(model.to_int(c)))] for c in codes] + [()] * 3
    got = run_cycles(chain, steps, lambda ctx: (group_of(ctx, chain.decoder.group), ctx.get(chain.aligner.offset)),
                     name=test_name)
    assert got[-1][1] == slip
    want, rd = [], "-"
    for code in codes:
        byte, control, *_, rd = model.decode(code, rd)
        want.append((byte, control, 0, 0))
    groups = [group for group, _ in got]
    # out of the aligner and the decoder two cycles after the word that ends it (zeros before the
    # first code-group make it look whole from the first word); the last one is never whole
    assert groups[2:1 + len(codes)] == want[:-1]


def test_a_slipped_bit_is_recovered_at_the_next_comma(test_name):
    """One bit slips in the middle of a run of idles: a few code-groups are bad, the aligner
    moves its boundary on the next comma, and the synchroniser is in sync again after it, as the
    model's machine says for the code-groups received."""
    codes = idles(80)
    chain = Chain(aligner=True, sync=True)
    line, steps = Line(3), []
    for n, code in enumerate(codes):
        if n == 41:
            line.slip()
        steps.append([(chain.aligner.bits, line.word(model.to_int(code)))])
    got = run_cycles(chain, steps, lambda ctx: (ctx.get(chain.aligner.offset), ctx.get(chain.aligner.slips),
                                                ctx.get(chain.sync.sync_status), group_of(ctx, chain.decoder.group)),
                     name=test_name)
    offsets = [offset for offset, *_ in got]
    assert offsets[20] == 3 and offsets[-1] == 4
    assert got[-1][1] == 2
    status = [bool(s) for _, _, s, _ in got]
    assert status[-1] and all(status[10:40])
    bad = sum(1 for *_, g in got[40:] if g[2] or g[3])
    assert 0 < bad < 4
