#!/usr/bin/env python3
"""Publish and receive rates of the Python package next to the C API's (cosmic-client-peer), on
LCM and DDS. Prints figures, never fails on them; not run by ctest. From the source tree:

    scripts/netns-run env PYTHONPATH=build/lib/python /usr/bin/python3 tests/python/benchmark.py --build build

Rows: publish = events per second one publish loop achieves, nobody subscribed; receive = events
per second a subscriber takes while the C peer publishes as fast as it can (first to last event;
received/sent shows what was lost on the way, LCM being UDP without repair).
"""
from __future__ import annotations

import argparse
import json
import subprocess
import threading
import time
from pathlib import Path

import numpy as np

import cosmic

SEGMENTS = {"lcm": "lcm:udpm://239.255.76.67:7999?ttl=0", "dds": "dds:40"}
PAYLOAD = 16


def peer_json(process: subprocess.Popen) -> dict:
    out, _ = process.communicate(timeout=120)
    return json.loads(out.strip().splitlines()[-1])


def start_peer(peer: str, *args: str) -> subprocess.Popen:
    process = subprocess.Popen([peer, *args], stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, text=True)
    assert process.stdout.readline().strip() == "READY"
    return process


def python_publish_rate(segment: str, count: int, data) -> float:
    with cosmic.Client(segment) as client:
        channel = client.announce("bench_py_pub", 0x2391, payload=PAYLOAD, roles="publish")
        sent = 0
        start = time.perf_counter()
        for _ in range(count):
            sent += channel.publish(data)  # False: the transport's queue was full
        return sent / (time.perf_counter() - start)


def python_receive(peer: str, segment: str, count: int, polling: bool) -> tuple[int, float]:
    name = f"bench_rx_{'poll' if polling else 'cb'}"
    with cosmic.Client(segment) as client:
        channel = client.announce(name, 0x2392, payload=PAYLOAD, roles="subscribe")
        times: list[float] = []
        done = threading.Event()
        if not polling:
            def on_event(event: cosmic.Event) -> None:
                times.append(time.perf_counter())
                if len(times) >= count:
                    done.set()
            channel.subscribe(on_event)
        publisher = start_peer(peer, "pub", "--segment", segment, "--channel", f"{name}:0x2392", "--payload", str(PAYLOAD),
                               "--count", str(count), "--delay-s", "1.5")
        if polling:
            deadline = time.monotonic() + 30
            while len(times) < count and time.monotonic() < deadline:
                if channel.get_event(timeout=0.2 if times else 5) is not None:
                    times.append(time.perf_counter())
                elif times:
                    break  # the flood is over
            peer_json(publisher)
        else:
            peer_json(publisher)
            done.wait(timeout=5)  # what is still on its way; less when events were lost
        n = len(times)
        return n, (n - 1) / (times[-1] - times[0]) if n > 1 else 0.0


def c_rates(peer: str, segment: str, count: int) -> tuple[float, int, float]:
    alone = start_peer(peer, "pub", "--segment", segment, "--channel", "bench_c_pub:0x2393", "--payload", str(PAYLOAD),
                       "--count", str(count))
    publish = peer_json(alone)["rate"]
    sub = start_peer(peer, "sub", "--segment", segment, "--channel", "bench_c_rx:0x2394", "--payload", str(PAYLOAD),
                     "--count", str(count), "--seconds", "20")
    pub = start_peer(peer, "pub", "--segment", segment, "--channel", "bench_c_rx:0x2394", "--payload", str(PAYLOAD),
                     "--count", str(count), "--delay-s", "1.5")
    peer_json(pub)
    received = peer_json(sub)
    return publish, received["received"], received["rate"]


def main() -> int:
    parser = argparse.ArgumentParser(description="Python vs. C API publish and receive rates")
    parser.add_argument("--build", default="build", help="build directory with tests/python/cosmic-client-peer")
    parser.add_argument("--count", type=int, default=50000)
    args = parser.parse_args()
    peer = str(Path(args.build) / "tests" / "python" / "cosmic-client-peer")
    print(f"{'segment':8} {'what':36} {'events/s':>10}  received/sent")
    for kind, segment in SEGMENTS.items():
        c_publish, c_received, c_receive = c_rates(peer, segment, args.count)
        rows = [
            ("C API publish", c_publish, ""),
            ("Python publish (bytes)", python_publish_rate(segment, args.count, bytes(PAYLOAD)), ""),
            ("Python publish (numpy array)", python_publish_rate(segment, args.count, np.zeros(PAYLOAD // 4, "<f4")), ""),
            ("C API receive (callback)", c_receive, f"{c_received}/{args.count}"),
        ]
        n, rate = python_receive(peer, segment, args.count, polling=False)
        rows.append(("Python receive (callback)", rate, f"{n}/{args.count}"))
        n, rate = python_receive(peer, segment, args.count, polling=True)
        rows.append(("Python receive (get_event loop)", rate, f"{n}/{args.count}"))
        for what, rate, ratio in rows:
            print(f"{kind:8} {what:36} {rate:10.0f}  {ratio}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
