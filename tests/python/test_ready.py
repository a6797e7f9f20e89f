"""Waiting until a channel is carried (issue 40): Channel.wait_ready() and announce(..., ready=T).

Without a peer the wait ends in cosmic.NotReadyError (a TimeoutError) naming what is missing; with
one (a C++ component, another Python client, or cosmicd's own endpoint) it returns, and the first
event published after it arrives without any probing. LCM has no discovery: it returns at once."""
from __future__ import annotations

import time

import pytest

import cosmic
from conftest import GATEWAY_DDS_DOMAIN, GATEWAY_LCM_URL, SOURCE_DIR, wait_until

DOMAIN = "dds:9"  # no other test uses it: nothing else can match these channels
ROBOT = str(SOURCE_DIR / "config" / "robot.yaml")


def test_announce_ready_without_a_peer_raises_not_ready():
    with cosmic.Client(DOMAIN) as client:
        start = time.monotonic()
        with pytest.raises(cosmic.NotReadyError) as raised:
            client.announce("py_ready_alone", 0x2361, payload=4, roles="publish", ready=0.2)
        assert time.monotonic() - start >= 0.2
        error = raised.value
        assert isinstance(error, TimeoutError) and isinstance(error, cosmic.Error)
        assert error.code == cosmic.E_TIMEOUT == -7
        for part in ("channel 'py_ready_alone'", f"'{DOMAIN}'", "publish (no reader", "after waiting"):
            assert part in error.message, error.message
        assert "COSMIC_E_TIMEOUT" in str(error)


def test_wait_ready_subscriber_without_a_writer_then_with_one():
    with cosmic.Client(DOMAIN) as sub_client, cosmic.Client(DOMAIN) as pub_client:
        listener = sub_client.announce("py_ready_pair", 0x2362, payload=4, roles="subscribe")
        with pytest.raises(cosmic.NotReadyError, match=r"subscribe \(no writer"):
            listener.wait_ready(0.1)
        with pytest.raises(cosmic.InvalidError, match="timeout"):
            listener.wait_ready(-1)
        talker = pub_client.announce("py_ready_pair", 0x2362, payload=4, roles="publish", ready=10)
        listener.wait_ready(10)
        assert talker.publish(b"\x01\x02\x03\x04")  # the first event, once: no probing
        event = listener.get_event(timeout=10)
        assert event is not None and event.payload == b"\x01\x02\x03\x04"


def test_ready_with_a_cpp_subscriber_carries_the_first_event(peer):
    sink = peer("sub", "--segment", DOMAIN, "--channel", "py_ready_peer:0x2363", "--payload", "4", "--count", "1",
                "--seconds", "30")
    with cosmic.Client(DOMAIN) as client:
        start = time.monotonic()
        out = client.announce("py_ready_peer", 0x2363, payload=4, omission_degree=3, roles="publish", ready=10)
        assert time.monotonic() - start < 10
        assert out.publish(b"once")  # one event: the peer exits 0 once it counted it
        wait_until(lambda: sink.process.poll() is not None, 15, "the C++ subscriber received the one event")
    assert sink.process.returncode == 0, sink.stop()


def test_ready_waits_for_the_gateways_own_endpoints(gateway):
    """The issue's case: a simulator on DDS knows when cosmicd's reader of its channel matched its
    writer, and its first event then crosses the gateway, without probing. py_command is published
    on the gateway's DDS segment (cosmicd reads it there), py_range subscribed (cosmicd writes it)."""
    # Roles count apart: cosmicd only reads py_command there, so a subscriber finds no writer.
    with cosmic.Client(f"dds:{GATEWAY_DDS_DOMAIN}") as listener:
        with pytest.raises(cosmic.NotReadyError, match=r"subscribe \(no writer"):
            listener.announce("py_command", 0x2302, payload=16, omission_degree=3, roles="subscribe", ready=0.3)
    with cosmic.Client(f"dds:{GATEWAY_DDS_DOMAIN}") as lan, cosmic.Client(f"lcm:{GATEWAY_LCM_URL}") as viz:
        to_lcm = viz.announce("py_command", 0x2302, payload=16, omission_degree=3, roles="subscribe", ready=0)
        command = lan.announce("py_command", 0x2302, payload=16, omission_degree=3, roles="publish", ready=10)
        assert command.publish(b"first command")
        event = to_lcm.get_event(timeout=10)
        assert event is not None and event.payload == b"first command"

        # cosmicd writes py_range here. A subscriber's ready is its reader's side of the match; the
        # gateway's writer matches on its side about then (docs/components.md), so the events are
        # repeated until one arrived.
        from_lcm = viz.announce("py_range", 0x2301, payload=16, omission_degree=3, roles="publish", ready=0)
        ranges = lan.announce("py_range", 0x2301, payload=16, omission_degree=3, roles="subscribe", ready=10)
        wait_until(lambda: ranges.get_event(timeout=0.01) is not None, 10, "a range through cosmicd",
                   step=lambda: from_lcm.publish(b"range"))


def test_lcm_is_ready_at_once():
    with cosmic.Client("lcm:udpm://239.255.76.67:7941?ttl=0") as client:
        start = time.monotonic()
        distance = client.announce_from(ROBOT, "distance", roles="publish", ready=10)
        distance.wait_ready(10)
        assert time.monotonic() - start < 1


def test_wait_ready_on_a_closed_client():
    client = cosmic.Client("lcm:udpm://239.255.76.67:7941?ttl=0")
    channel = client.announce("py_ready_closed", 0x2364, payload=4, roles="publish")
    client.close()
    with pytest.raises(cosmic.ClosedError):
        channel.wait_ready(1)


def test_wait_ready_inside_a_callback_is_refused():
    url = "lcm:udpm://239.255.76.67:7941?ttl=0"
    with cosmic.Client(url) as pub_client, cosmic.Client(url) as sub_client:
        out = pub_client.announce("py_ready_callback", 0x2365, payload=4, roles="publish")
        listener = sub_client.announce("py_ready_callback", 0x2365, payload=4, roles="subscribe")
        raised: list[BaseException] = []

        def callback(event: cosmic.Event) -> None:
            try:
                listener.wait_ready(0)
            except cosmic.Error as e:
                raised.append(e)

        listener.subscribe(callback)
        wait_until(lambda: raised, 15, "the callback ran", step=lambda: out.publish(b"ping"))
        assert isinstance(raised[0], cosmic.InvalidError) and "inside the callback" in str(raised[0])
