#!/usr/bin/env python3
"""A simulated distance sensor: the robot's `distance` channel (config/robot.yaml: HRT, one event
every 10 ms, 4 bytes) published from a numpy model of the robot driving up to a wall and back.

    PYTHONPATH=build/lib/python /usr/bin/python3 examples/python/distance_sensor.py --segment dds:0

The channel's model comes from the gateway's own configuration (cosmic.load_channel), so the
simulated sensor announces exactly what the real one does; a subscriber cannot tell them apart.
The event is the distance in metres as a little-endian float32; the numpy array holding it is
published from its own memory, without a copy.
"""
from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

import cosmic

ROBOT_YAML = Path(__file__).resolve().parents[2] / "config" / "robot.yaml"


def true_distance(t: float, start_m: float, speed_mps: float, closest_m: float) -> float:
    """The robot drives towards the wall at `speed_mps` until `closest_m`, then backs off: a triangle wave."""
    span = start_m - closest_m
    travelled = (speed_mps * t) % (2 * span)
    return start_m - (travelled if travelled <= span else 2 * span - travelled)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--config", default=str(ROBOT_YAML), help="gateway configuration with the channel (default: %(default)s)")
    parser.add_argument("--channel", default="distance")
    parser.add_argument("--segment", default="dds:0", help="where the sensor lives (default: %(default)s)")
    parser.add_argument("--seconds", type=float, default=10.0, help="how long to run (default: %(default)s)")
    parser.add_argument("--noise", type=float, default=0.005, help="sensor noise, standard deviation in m")
    args = parser.parse_args()

    desc = cosmic.load_channel(args.config, args.channel)
    if desc.payload < 4:
        parser.error(f"channel {desc.name} carries {desc.payload} B, the float32 reading needs 4")
    period = desc.period or 0.01
    rng = np.random.default_rng(seed=23)
    reading = np.zeros(1, dtype="<f4")  # the event's 4 bytes, refilled in place every period

    with cosmic.Client(args.segment) as segment:
        sensor = segment.announce(desc, roles=cosmic.PUBLISH)
        print(f"publishing {desc.name} ({desc.cls}, every {period * 1e3:g} ms) on {args.segment}")
        start = next_step = time.monotonic()
        published = 0
        while (now := time.monotonic()) - start < args.seconds:
            reading[0] = true_distance(now - start, start_m=3.0, speed_mps=0.5, closest_m=0.2) + rng.normal(0.0, args.noise)
            if sensor.publish(reading):
                published += 1
            if published % round(1 / period) == 0:
                print(f"t={now - start:5.2f} s  distance {reading[0]:.3f} m")
            next_step += period
            time.sleep(max(0.0, next_step - time.monotonic()))
    print(f"{published} events in {args.seconds:g} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
