"""The PCS's 8b/10b encoder and decoder in the Amaranth simulator, against
:mod:`sim.models.pcs_model`'s tables, written apart (``test_pcs_model_oracle`` keeps them apart)."""

from hypothesis import given, settings
from hypothesis import strategies as st

from gateware.pcs.code_groups import Decoder, Encoder
from sim.models import pcs_model as model
from sim.models.pcs_stim import Chain, group_of, run_cycles

CODES = [(byte, 0) for byte in range(256)] + [(byte, 1) for byte in model.CONTROLS.values()]
K28_5 = model.CONTROLS["K28.5"]


def every_code_from_both_disparities():
    """``(byte, control)`` to send so that each of :data:`CODES` goes out once from each
    running disparity: K28.5 (which always turns it) sent before one where needed."""
    sent, rd = [], "-"
    for want in "-+":
        for code in CODES:
            if rd != want:
                sent.append((K28_5, 1))
                _, rd = model.encode(K28_5, 1, rd)
            sent.append(code)
            _, rd = model.encode(*code, rd)
    return sent


def model_codes(sent, rd="-"):
    out = []
    for byte, control in sent:
        code, rd = model.encode(byte, control, rd)
        out.append(code)
    return out


def test_every_code_group_encodes_as_the_tables_say(test_name):
    """The 256 data bytes and the 12 control codes, each from both running disparities, encode
    as the model's tables give them."""
    sent = every_code_from_both_disparities()
    dut = Encoder()
    got = run_cycles(dut, [((dut.data, b), (dut.control, k)) for b, k in sent],
                     lambda ctx: ctx.get(dut.code), name=test_name)
    assert [model.to_bits(code) for code in got] == model_codes(sent)
    assert len(sent) >= 2 * len(CODES) == 536


def test_every_code_group_decodes_back(test_name):
    """The same code-groups into the decoder: each byte back, none flagged."""
    sent = every_code_from_both_disparities()
    dut = Decoder()
    got = run_cycles(dut, [[(dut.code, model.to_int(code))] for code in model_codes(sent)],
                     lambda ctx: group_of(ctx, dut.group), name=test_name)
    assert got == [(byte, control, 0, 0) for byte, control in sent]


def test_every_ten_bit_value_is_judged_as_the_model_judges_it(test_name):
    """All 1,024 values, each from both running disparities (an unbalanced value turns the
    decoder's): those in no column give ``code_error``, those in the other column
    ``disparity_error``, the rest their byte, and the running disparity follows the bits."""
    values = [v for v in range(1024) for _ in range(2)]
    dut = Decoder()
    got = run_cycles(dut, [[(dut.code, v)] for v in values],
                     lambda ctx: (*group_of(ctx, dut.group), ctx.get(dut.disparity)), name=test_name)
    rd, flagged = "-", {"code": 0, "disparity": 0}
    for value, (byte, control, code_error, disparity_error, after) in zip(values, got, strict=True):
        m_byte, m_control, m_code_error, m_disparity_error, rd = model.decode(model.to_bits(value), rd)
        assert (code_error, disparity_error) == (m_code_error, m_disparity_error), model.to_bits(value)
        if not code_error:
            assert (byte, control) == (m_byte, m_control), model.to_bits(value)
        assert after == (rd == "+")
        flagged["code"] += code_error
        flagged["disparity"] += disparity_error
    # 1024 values less the 464 of the tables (data and control, either column) have no meaning
    assert flagged["code"] == 2 * (1024 - 464)
    assert flagged["disparity"] > 0


def test_a_code_group_from_the_wrong_disparity_is_flagged(test_name):
    """D.0.1, which turns the running disparity positive, sent twice from a negative one: the
    second is in the wrong column; the third, from the positive column, is right again."""
    first, rd = model.encode(0x20, 0, "-")
    codes = [first, first, model.encode(0x20, 0, "+")[0]]
    dut = Decoder()
    got = run_cycles(dut, [[(dut.code, model.to_int(c))] for c in codes],
                     lambda ctx: group_of(ctx, dut.group), name=test_name)
    assert rd == "+"
    assert got == [(0x20, 0, 0, 0), (0x20, 0, 0, 1), (0x20, 0, 0, 0)]


@settings(max_examples=30, deadline=None)
@given(st.lists(st.tuples(st.integers(0, 255), st.booleans()), min_size=1, max_size=200))
def test_random_streams_through_encoder_and_decoder(stream):
    """Random bytes, some as control codes, through the encoder into the decoder: the same
    bytes out, never flagged, with the model's code-groups on the line."""
    controls = list(model.CONTROLS.values())
    sent = [(controls[b % len(controls)], 1) if k else (b, 0) for b, k in stream]
    chain = Chain(encoder=True)
    steps = [((chain.encoder.data, b), (chain.encoder.control, k)) for b, k in sent] + [()]
    got = run_cycles(chain, steps,
                     lambda ctx: (ctx.get(chain.encoder.code), group_of(ctx, chain.decoder.group)),
                     name="pcs_random_streams")
    assert [model.to_bits(code) for code, _ in got[:-1]] == model_codes(sent)
    assert [group for _, group in got[1:]] == [(b, k, 0, 0) for b, k in sent]

