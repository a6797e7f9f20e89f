#!/usr/bin/env python3
"""A simulation block with a fixed step, as the paper's Simulink integration (Fig. 9): the robot's
obstacle detector. Each step it polls `get_event` for the distance events that arrived since the
last step (the tool's time is synchronous and periodic; the sensors publish when they like), keeps
the newest, and publishes `obstacle` (1 byte, non-zero = obstacle ahead) for the step.

    PYTHONPATH=build/lib/python /usr/bin/python3 examples/python/fixed_step_block.py --segment dds:0 &
    PYTHONPATH=build/lib/python /usr/bin/python3 examples/python/distance_sensor.py --segment dds:0

Both channels, class and QoS included, come from config/robot.yaml.
"""
from __future__ import annotations

import argparse
import struct
import time
from pathlib import Path

import cosmic

ROBOT_YAML = Path(__file__).resolve().parents[2] / "config" / "robot.yaml"


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--config", default=str(ROBOT_YAML))
    parser.add_argument("--segment", default="dds:0", help="where the block lives (default: %(default)s)")
    parser.add_argument("--step", type=float, default=0.01, help="the block's fixed step in s (default: %(default)s)")
    parser.add_argument("--seconds", type=float, default=15.0)
    parser.add_argument("--threshold", type=float, default=0.5, help="an obstacle is closer than this, in m")
    args = parser.parse_args()

    with cosmic.Client(args.segment) as segment:
        distance = segment.announce_from(args.config, "distance", roles=cosmic.SUBSCRIBE)
        obstacle = segment.announce_from(args.config, "obstacle", roles=cosmic.PUBLISH)
        newest: float | None = None
        events = steps = 0
        start = next_step = time.monotonic()
        while time.monotonic() - start < args.seconds:
            # get_event: whatever arrived since the last step, without waiting (timeout 0).
            while (event := distance.get_event()) is not None:
                (newest,) = struct.unpack("<f", event.payload)
                events += 1
            ahead = newest is not None and newest < args.threshold
            obstacle.publish(b"\x01" if ahead else b"\x00")
            steps += 1
            if steps % round(1 / args.step) == 0:
                shown = "none yet" if newest is None else f"{newest:.3f} m"
                print(f"step {steps:5d}  events so far {events:5d}  distance {shown}  obstacle {'YES' if ahead else 'no'}")
            next_step += args.step
            time.sleep(max(0.0, next_step - time.monotonic()))
    print(f"{steps} steps, {events} distance events")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
