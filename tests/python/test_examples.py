"""The examples of examples/python run: the simulated sensor feeds the fixed-step block."""
from __future__ import annotations

import os
import re
import subprocess
import sys

from conftest import SOURCE_DIR

SEGMENT = "lcm:udpm://239.255.76.67:7991?ttl=0"


def test_the_simulated_sensor_feeds_the_fixed_step_block():
    examples = SOURCE_DIR / "examples" / "python"
    env = dict(os.environ)
    block = subprocess.Popen([sys.executable, str(examples / "fixed_step_block.py"), "--segment", SEGMENT, "--seconds", "4"],
                             stdout=subprocess.PIPE, text=True, env=env)
    sensor = subprocess.run([sys.executable, str(examples / "distance_sensor.py"), "--segment", SEGMENT, "--seconds", "2"],
                            capture_output=True, text=True, env=env, timeout=60)
    out, _ = block.communicate(timeout=60)
    assert sensor.returncode == 0, sensor.stderr
    assert block.returncode == 0
    events = int(re.search(r"(\d+) distance events", out).group(1))
    assert events >= 50, out  # 2 s at 100 Hz; the block may start listening a little late
