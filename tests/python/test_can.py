"""The Python package on a CAN bus (issue 23, item 5): a Python component on vcan0 (`can:vcan0?node=N`,
libcosmic-client's SocketCAN transport with the gateway's GET_ETAG binding) and a Python component
on an LCM group, through a real cosmicd, both ways. Needs SocketCAN: ctest's python.can runs it
inside scripts/can-vm; elsewhere (python.client on a host without vcan0) it is skipped."""
from __future__ import annotations

import subprocess
import tempfile
import time
from pathlib import Path
from typing import Iterator

import numpy as np
import pytest

import cosmic
from conftest import Gateway, wait_until

pytestmark = pytest.mark.skipif(not Path("/sys/class/net/vcan0").exists(),
                                reason="needs vcan0 (ctest python.can runs this file in scripts/can-vm)")

LCM_URL = "udpm://239.255.76.67:7961?ttl=0"
RANGE = cosmic.ChannelDesc("can_range", 0x2401, cls="nrt", payload=16, omission_degree=3)
COMMAND = cosmic.ChannelDesc("can_command", 0x2402, cls="nrt", payload=4, omission_degree=3)
CONFIG = f"""gateway: {{name: py-can-gw, can_node_id: 1}}
segments:
  - {{name: body, type: can, interface: vcan0, bitrate: 500kbit/s}}
  - {{name: viz, type: lcm, url: "{LCM_URL}", latency_bound: 2ms}}
channels:
  - {{name: can_range, subject: 0x2401, class: nrt, payload: 16B, omission_degree: 3, publishers: [body], subscribers: [viz]}}
  - {{name: can_command, subject: 0x2402, class: nrt, payload: 4B, omission_degree: 3, publishers: [viz], subscribers: [body]}}
"""


@pytest.fixture(scope="module")
def can_gateway() -> Iterator[Gateway]:
    subprocess.run(["ip", "link", "set", "vcan0", "up"], check=False)
    with tempfile.TemporaryDirectory(prefix="cosmic-py-can-") as work:
        g = Gateway(Path(work), CONFIG)
        yield g
        g.stop()
        g.print_log_if_it_failed()


def test_a_python_can_sensor_reaches_an_lcm_subscriber(can_gateway):
    with cosmic.Client("can:vcan0?node=5") as body, cosmic.Client(f"lcm:{LCM_URL}") as viz:
        sensor = body.announce(RANGE, roles=cosmic.PUBLISH)  # binds its etag through GET_ETAG
        subscriber = viz.announce(RANGE, roles=cosmic.SUBSCRIBE)
        seen: set[bytes] = set()

        def poll() -> None:
            while (e := subscriber.get_event(timeout=0.02)) is not None:
                assert e.subject == RANGE.subject
                seen.add(e.payload)

        # 16 bytes: two fragments of the CAN wire format each.
        ranges = [np.array([k * 0.5, k * 0.25], dtype="<f8") for k in range(20)]
        wait_until(lambda: ranges[0].tobytes() in seen, 20, "the first range through cosmicd",
                   step=lambda: (sensor.publish(ranges[0]), poll()))
        for r in ranges[1:]:
            assert sensor.publish(r)
            time.sleep(0.005)
        wait_until(lambda: {r.tobytes() for r in ranges} <= seen, 15, "all 20 ranges on LCM", step=poll)


def test_an_lcm_command_reaches_a_python_can_actuator(can_gateway):
    with cosmic.Client(f"lcm:{LCM_URL}") as viz, cosmic.Client("can:vcan0?node=6") as body:
        operator = viz.announce(COMMAND, roles=cosmic.PUBLISH)
        actuator = body.announce(COMMAND, roles=cosmic.SUBSCRIBE)
        received: list[bytes] = []
        actuator.subscribe(lambda e: received.append(e.payload))
        wait_until(lambda: b"ping" in received, 20, "the actuator bound and receiving", step=lambda: operator.publish(b"ping"))
        commands = [k.to_bytes(4, "little") for k in range(20)]
        for c in commands:
            operator.publish(c)
            time.sleep(0.005)
        wait_until(lambda: set(commands) <= set(received), 15, "all 20 commands on CAN")
        assert [c for c in received if c in commands] == commands  # in order


def test_check_channel_of_the_can_channels(can_gateway):
    assert cosmic.check_channel(can_gateway.socket, "can_range") == "bound"
    assert cosmic.check_channel(can_gateway.socket, "can_command") == "bound"
