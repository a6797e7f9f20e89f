"""Python and a C++ component (cosmic-client-peer, on libcosmic-client) on one DDS domain and on
one LCM group: every event crosses both ways (Python -> C++ -> Python), bytes and identity intact."""
from __future__ import annotations

import time

import numpy as np
import pytest

import cosmic
from conftest import wait_until

SEGMENTS = {"dds": "dds:7", "lcm": "lcm:udpm://239.255.76.67:7951?ttl=0"}
SUBJECTS = {"dds": (0x2311, 0x2312), "lcm": (0x2313, 0x2314)}


@pytest.mark.parametrize("kind", ["dds", "lcm"])
def test_events_cross_both_ways_with_a_cpp_component(kind, peer):
    segment = SEGMENTS[kind]
    to_subject, from_subject = SUBJECTS[kind]
    to_peer, from_peer = f"py_to_peer_{kind}", f"py_from_peer_{kind}"
    echo = peer("echo", "--segment", segment, "--in", f"{to_peer}:{to_subject}", "--out", f"{from_peer}:{from_subject}",
                "--payload", "32")
    with cosmic.Client(segment) as client:
        out = client.announce(to_peer, to_subject, payload=32, omission_degree=3, roles=cosmic.PUBLISH)
        back = client.announce(from_peer, from_subject, payload=32, omission_degree=3, roles=cosmic.SUBSCRIBE)
        received: list[cosmic.Event] = []
        back.subscribe(received.append)
        # DDS discovery takes its time: a probe goes out until its echo is back.
        wait_until(lambda: received, 20, "the first echo", step=lambda: out.publish(b"probe"))

        sent = [f"event {k:04d}".encode() for k in range(50)]
        for payload in sent:  # paced: a DDS writer keeps only omission_degree + 1 samples for repair
            assert out.publish(payload)
            time.sleep(0.002)
        samples = np.arange(8, dtype="<i4") * 1000  # a numpy array, published from its own memory
        assert out.publish(samples)
        wait_until(lambda: set(sent) | {samples.tobytes()} <= {e.payload for e in received}, 15, "all 51 echoes")
        first = next(e for e in received if e.payload == sent[0])
        assert (first.subject, first.channel) == (from_subject, from_peer)
        assert first.sequence > 0
        assert np.array_equal(np.frombuffer(next(e.payload for e in received if len(e.payload) == 32), "<i4"), samples)

        # The same channel polled instead: the peer's events wait for get_event().
        back.unsubscribe()
        out.publish(b"polled")
        wait_until(lambda: (e := back.get_event(timeout=0.5)) is not None and e.payload == b"polled", 15, "the polled echo")
    assert '"echoed":' in echo.stop()


def test_cpp_component_receives_what_python_publishes_on_dds(peer):
    """Python -> C++ alone, as a stream: the peer's callback counts 200 events (its exit status
    says whether they came). Paced at 2 ms: the writer keeps only omission_degree + 1 samples."""
    sink = peer("sub", "--segment", "dds:8", "--channel", "py_sink:0x2315", "--payload", "16", "--count", "200",
                "--seconds", "60")
    with cosmic.Client("dds:8") as client:
        out = client.announce("py_sink", 0x2315, payload=16, omission_degree=3, roles="publish")
        k = 0

        def publish_next() -> None:
            nonlocal k
            out.publish(k.to_bytes(16, "little"))
            k += 1
            time.sleep(0.002)

        wait_until(lambda: sink.process.poll() is not None, 40, "the C++ subscriber counted 200 events", step=publish_next)
    assert sink.process.returncode == 0, sink.stop()
