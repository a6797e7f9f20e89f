"""Every error path of the package: an exception carrying the C code and the reason."""
from __future__ import annotations

import socket
import tempfile
from pathlib import Path

import numpy as np
import pytest

import cosmic
from conftest import SOURCE_DIR, wait_until

LCM = "lcm:udpm://239.255.76.67:7961?ttl=0"
ROBOT = str(SOURCE_DIR / "config" / "robot.yaml")


@pytest.mark.parametrize("segment", ["", "dds", "dds:x", "dds:0?colour=red", "lcm:tcp://x", "can:vcan0", "can:vcan0?node=200", "zenoh:0"])
def test_bad_segment_strings(segment):
    with pytest.raises(cosmic.InvalidError) as raised:
        cosmic.Client(segment)
    assert raised.value.code == cosmic.E_INVALID
    assert raised.value.message and isinstance(raised.value, ValueError)


def test_a_missing_can_interface_is_a_transport_error():
    with pytest.raises(cosmic.TransportError) as raised:
        cosmic.Client("can:nosuchcan0?node=5")
    assert raised.value.code == cosmic.E_TRANSPORT and "nosuchcan0" in raised.value.message


def test_payload_too_large_and_wrong_roles():
    with cosmic.Client(LCM) as client:
        distance = client.announce_from(ROBOT, "distance", roles="publish")
        with pytest.raises(cosmic.TooLargeError) as raised:
            distance.publish(b"12345")
        assert raised.value.code == cosmic.E_TOO_LARGE and "payload is 4 B" in raised.value.message
        with pytest.raises(cosmic.TooLargeError):
            distance.publish(np.zeros(2, dtype="<f4"))  # 8 bytes
        assert distance.publish(np.zeros(1, dtype="<f4"))
        for call in (lambda: distance.subscribe(print), distance.unsubscribe, distance.get_event):
            with pytest.raises(cosmic.InvalidError, match="announced to publish only"):
                call()
        listener = client.announce_from(ROBOT, "obstacle", roles="subscribe")
        with pytest.raises(cosmic.InvalidError, match="announced to subscribe only") as raised:
            listener.publish(b"\x01")
        assert raised.value.code == cosmic.E_INVALID
        with pytest.raises(cosmic.InvalidError, match="timeout"):
            listener.get_event(timeout=-1)
        with pytest.raises(TypeError):
            listener.subscribe("not callable")


def test_what_publish_accepts():
    with cosmic.Client(LCM) as client:
        channel = client.announce("py_buffers", 0x2321, payload=64, roles="publish")
        for data in (b"", b"abc", bytearray(8), memoryview(b"12345678")[2:6], np.arange(4, dtype=np.uint16)):
            assert channel.publish(data) is True
        with pytest.raises(TypeError):
            channel.publish("text is not bytes")
        with pytest.raises((BufferError, ValueError)):
            channel.publish(np.arange(16, dtype=np.uint8).reshape(4, 4)[:, 1])  # not contiguous


def test_bad_channel_descriptions():
    with cosmic.Client(LCM) as client:
        with pytest.raises(cosmic.InvalidError, match="subject"):
            client.announce("no_subject", roles="publish")
        with pytest.raises(cosmic.InvalidError, match="subject other than 0"):
            client.announce("zero", 0, roles="publish")
        with pytest.raises(cosmic.InvalidError, match="cls"):
            client.announce("c", 1, cls="urgent", roles="publish")
        with pytest.raises(cosmic.InvalidError, match="role"):
            client.announce("c", 1, roles="shout")
        with pytest.raises(cosmic.InvalidError, match="roles"):
            client.announce("c", 1, roles=0)
        with pytest.raises(cosmic.InvalidError):
            client.announce("c", 1, period="10 parsecs", roles="publish")
        with pytest.raises(cosmic.InvalidError):
            client.announce("c", 1, period=-0.01, roles="publish")
        with pytest.raises(TypeError):
            client.announce("c", 1, period=[10], roles="publish")
        # Both forms of a duration reach the C API as whole nanoseconds.
        assert cosmic.parse_duration_ns("10ms") == 10_000_000
        assert client.announce("durations", 0x2322, period="10ms", reaction_time=0.005, temp_validity=1, roles="publish")


def test_load_channel_errors():
    with pytest.raises(cosmic.InvalidError, match=r"no channel 'nope' in .*channels: distance, acceleration"):
        cosmic.load_channel(ROBOT, "nope")
    with tempfile.TemporaryDirectory() as work:
        bad = Path(work, "bad.yaml")
        bad.write_text("segments:\n  - {name: lan, type: dds, domain: 0}\nchannels:\n  - {name: x, subject: 1, class: fast}\n")
        with pytest.raises(cosmic.InvalidError, match=r"bad\.yaml:4:\d+: channels\[0\]"):
            cosmic.load_channel(str(bad), "x")
        with pytest.raises(cosmic.InvalidError):
            cosmic.load_channel(str(Path(work, "missing.yaml")), "x")
    d = cosmic.load_channel(ROBOT, "command")
    assert (d.cls, d.period, d.reaction_time, d.payload) == ("srt", 0.05, 0.02, 4)  # max_rate 20Hz -> period 50 ms


def test_check_channel_with_no_gateway_there():
    with tempfile.TemporaryDirectory() as work:
        with pytest.raises(cosmic.UnavailableError) as raised:
            cosmic.check_channel(str(Path(work, "control.sock")), "distance")
        assert raised.value.code == cosmic.E_UNAVAILABLE and "control.sock" in raised.value.message
        # A socket that is bound but never answers: the query's own deadline, not a hang.
        silent = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        silent.bind(str(Path(work, "silent.sock")))
        silent.listen(1)
        peer = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        peer.connect(str(Path(work, "silent.sock")))  # fills the backlog: the next connect is refused or waits
        with pytest.raises(cosmic.UnavailableError):
            cosmic.check_channel(str(Path(work, "silent.sock")), "distance")
        peer.close()
        silent.close()


def test_a_closed_client_refuses_every_call():
    client = cosmic.Client(LCM)
    channel = client.announce("py_closed", 0x2323, payload=8, roles="publish")
    listener = client.announce("py_closed_in", 0x2327, payload=8, roles="subscribe")
    client.close()
    client.close()  # idempotent
    assert client.closed and "closed" in repr(channel)
    for call in (lambda: channel.publish(b"x"), listener.get_event, lambda: listener.subscribe(print), listener.unsubscribe,
                 lambda: client.announce("again", 0x2324, roles="publish")):
        with pytest.raises(cosmic.ClosedError) as raised:
            call()
        assert raised.value.code == cosmic.E_INVALID and isinstance(raised.value, cosmic.Error)
    with cosmic.Client(LCM) as scoped:
        pass
    assert scoped.closed


def test_what_a_callback_may_not_do_is_refused_inside_it():
    with cosmic.Client(LCM) as client, cosmic.Client(LCM) as publisher:
        one = client.announce("py_inside_one", 0x2325, payload=8, roles="subscribe")
        other = client.announce("py_inside_other", 0x2326, payload=8, roles="subscribe")
        out = publisher.announce("py_inside_one", 0x2325, payload=8, roles="publish")
        refusals: list[Exception] = []

        def callback(event: cosmic.Event) -> None:
            for forbidden in (client.close, lambda: other.subscribe(print), other.unsubscribe):
                try:
                    forbidden()
                except cosmic.InvalidError as e:
                    refusals.append(e)
            one.unsubscribe()  # its own channel: allowed, effective when the callback returns

        one.subscribe(callback)
        wait_until(lambda: len(refusals) >= 3, 10, "the callback ran", step=lambda: out.publish(b"x"))
        assert "close() from inside a callback" in refusals[0].message
        assert "from inside the callback of channel 'py_inside_one'" in refusals[1].message
        # Unsubscribed from inside: later events are queued for get_event().
        wait_until(lambda: (e := one.get_event(timeout=0.2)) is not None and e.payload == b"after", 10, "a queued event",
                   step=lambda: out.publish(b"after"))
