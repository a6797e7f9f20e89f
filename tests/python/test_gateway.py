"""Through a real cosmicd bridging a DDS domain and an LCM group (conftest.GATEWAY_YAML): a Python
publisher on one segment reaches a Python subscriber on the other; check_channel asks the gateway."""
from __future__ import annotations

import json
import time

import numpy as np
import pytest

import cosmic
from conftest import GATEWAY_DDS_DOMAIN, GATEWAY_LCM_URL, wait_until

RANGE = cosmic.ChannelDesc("py_range", 0x2301, cls="nrt", payload=16, omission_degree=3)
COMMAND = cosmic.ChannelDesc("py_command", 0x2302, cls="nrt", payload=16, omission_degree=3)


def gateway_counter(gateway, channel: str, segment: str, field: str) -> int:
    answer = json.loads(gateway.ctl("--json", "channels").stdout)
    for c in answer["channels"]:
        if c["name"] == channel:
            for s in c["segments"]:
                if s["segment"] == segment:
                    return s[field] or 0
    return -1


def test_lcm_publisher_reaches_dds_subscriber_through_cosmicd(gateway):
    with cosmic.Client(f"lcm:{GATEWAY_LCM_URL}") as viz, cosmic.Client(f"dds:{GATEWAY_DDS_DOMAIN}") as lan:
        publisher = viz.announce(RANGE, roles=cosmic.PUBLISH)
        subscriber = lan.announce(RANGE, roles=cosmic.SUBSCRIBE)
        seen: set[bytes] = set()

        def poll() -> None:  # a polling subscriber, as a fixed-step tool is
            while (e := subscriber.get_event(timeout=0.02)) is not None:
                assert e.subject == RANGE.subject
                seen.add(e.payload)

        wait_until(lambda: b"probe" in seen, 20, "the gateway's DDS writer matched",
                   step=lambda: (publisher.publish(b"probe"), poll()))
        ranges = [np.array([k * 0.5, k * 0.25], dtype="<f8") for k in range(30)]
        for r in ranges:  # paced: the gateway's DDS writer keeps omission_degree + 1 samples for repair
            assert publisher.publish(r)
            time.sleep(0.002)
        wait_until(lambda: {r.tobytes() for r in ranges} <= seen, 15, "all 30 ranges on DDS", step=poll)
    assert gateway_counter(gateway, "py_range", "viz", "rx") >= 31
    assert gateway_counter(gateway, "py_range", "lan", "tx") >= 31


def test_dds_publisher_reaches_lcm_subscriber_through_cosmicd(gateway):
    with cosmic.Client(f"dds:{GATEWAY_DDS_DOMAIN}") as lan, cosmic.Client(f"lcm:{GATEWAY_LCM_URL}") as viz:
        publisher = lan.announce(COMMAND, roles="publish")
        subscriber = viz.announce(COMMAND, roles="subscribe")
        received: list[bytes] = []
        subscriber.subscribe(lambda e: received.append(e.payload))
        wait_until(lambda: b"probe" in received, 20, "the gateway's DDS reader matched", step=lambda: publisher.publish(b"probe"))
        commands = [f"cmd {k}".encode() for k in range(30)]
        for c in commands:
            publisher.publish(c)
            time.sleep(0.002)
        wait_until(lambda: set(commands) <= set(received), 15, "all 30 commands on LCM")


def test_check_channel_asks_the_running_gateway(gateway):
    assert cosmic.check_channel(gateway.socket, "py_range") == "bound"
    assert cosmic.check_channel(gateway.socket, "py_command") == "bound"


def test_check_channel_of_a_channel_the_gateway_does_not_bind(gateway):
    with pytest.raises(cosmic.UnboundError) as raised:
        cosmic.check_channel(gateway.socket, "no_such_channel")
    assert raised.value.code == cosmic.E_UNBOUND
    assert "not_found" in raised.value.message
