"""Property-based (Hypothesis): frames built by scapy and the host encoder, then mutated at
random (a byte of the headers changed, the frame cut short or padded; or a byte of a record
changed, the record cut or lengthened, in a well-formed datagram), go through the endpoint
in the Amaranth simulator one by one. Each must land in exactly the counters the reference model
(:mod:`sim.models.net_model`, written from the RFCs and the protocol page, not from the gateware)
names, and nothing of a dropped frame may leak: no pixel, no register set, no reply, no
configuration change. Hypothesis draws a fresh seed each run and prints the failing example
(with the blob that replays it)."""

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from host import codec
from sim.models import frames
from sim.models.endpoint_traffic import COLUMNS, A, image_frame, sequencer_record
from sim.models.net_model import Model
from sim.tb import endpoint_sim
from spec import records
from spec.facts import TEST_DMD

#: Good frames of each kind the endpoint takes, before mutation.
BASES = [image_frame(0), image_frame(1, frame=1), frames.icmp_echo(A, bytes(range(24)), ident=3, seq=4),
         frames.arp_request(A), frames.udp(A, codec.status_query(9))]
#: Good records of each type, before mutation (then framed whole, checksums right).
RECORDS = [codec.image_record(2, 3 * COLUMNS, bytes(range(COLUMNS)), 0), codec.status_query(9),
           codec.control_record(1, bit_depth=6), sequencer_record(5)]
#: Counters the reference model keeps and the endpoint reports.
COUNTERS = [name for name, _ in records.NET_COUNTERS + records.RECORD_COUNTERS]

mutation = st.one_of(
    st.tuples(st.just("xor"), st.integers(0, 64), st.integers(1, 255)),   # a header byte changed
    st.tuples(st.just("cut"), st.integers(0, 80)),                        # cut to this many bytes
    st.tuples(st.just("pad"), st.integers(1, 40)),                        # bytes beyond the datagram
)


def mutate(raw, mutations):
    raw = bytearray(raw)
    for kind, *args in mutations:
        if kind == "xor" and args[0] < len(raw):
            raw[args[0]] ^= args[1]
        elif kind == "cut":
            del raw[max(args[0], 14):]
        elif kind == "pad":
            raw += bytes(range(args[0]))
    return bytes(raw)


frame_case = st.tuples(st.just("frame"), st.integers(0, len(BASES) - 1), st.lists(mutation, min_size=1, max_size=3))
record_case = st.tuples(st.just("record"), st.integers(0, len(RECORDS) - 1),
                        st.lists(mutation.map(lambda m: (m[0], m[1] % 24, *m[2:]) if m[0] != "pad" else m),
                                 min_size=1, max_size=3))


def build(kind, base, mutations):
    if kind == "frame":
        return mutate(BASES[base], mutations)
    record = bytearray(RECORDS[base])
    for what, *args in mutations:
        if what == "xor" and args[0] < len(record):
            record[args[0]] ^= args[1]
        elif what == "cut":
            del record[args[0]:]
        elif what == "pad":
            record += bytes(args[0])
    return frames.udp(A, bytes(record))


@settings(max_examples=6, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(st.one_of(frame_case, record_case), min_size=4, max_size=8))
def test_mutated_frames_land_where_the_reference_model_says(cases):
    sequence = [(BASES[0], False)] + [(build(*case), False) for case in cases]
    out = endpoint_sim.run(sequence, name="endpoint_fuzz", settle_each=200, gap=(0, 20), waves=False)
    model = Model(TEST_DMD, A.mac, A.ip, A.port)
    model.frame(sequence[0][0])
    snapshots = out["snapshots"]
    for k in range(1, len(sequence)):
        before = {name: model.counters[name] for name in COUNTERS}
        outcome = model.frame(*sequence[k])
        want = {name: model.counters[name] - before[name] for name in COUNTERS}
        got_before, got = snapshots[k - 1], snapshots[k]
        counted = {**got["net"], **got["app"]}
        counted_before = {**got_before["net"], **got_before["app"]}
        delta = {name: counted[name] - counted_before[name] for name in COUNTERS}
        assert delta == want, f"frame {k} ({outcome}): {sequence[k][0].hex()}"
        if outcome.startswith("drop_") or any(v for n, v in want.items() if n.startswith("drop_app")):
            assert got["pixel_count"] == got_before["pixel_count"], f"frame {k}: pixels of a dropped frame"
            assert got["register_count"] == got_before["register_count"], f"frame {k}: registers handed on"
            assert got["config"] == got_before["config"], f"frame {k}: configuration changed"
            assert got["tx_count"] == got_before["tx_count"], f"frame {k}: a dropped frame was answered"
