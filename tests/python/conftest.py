"""Fixtures of the Python package's tests (tests/python, run by ctest as python.client inside
scripts/netns-run): the C++ peer, a running cosmicd, and waiting on conditions with deadlines."""
from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Callable, Iterator, Optional

import pytest

if os.environ.get("COSMIC_IN_NETNS") != "1":
    pytest.exit("run through scripts/netns-run (ctest -R python.client does): DDS and LCM must stay on this host", 2)

COSMICD = os.environ["COSMICD"]
COSMICCTL = os.environ["COSMICCTL"]
PEER = os.environ["COSMIC_CLIENT_PEER"]
SOURCE_DIR = Path(os.environ["COSMIC_SOURCE_DIR"])

# The gateway's segments: a DDS domain of their own and an LCM group of their own, apart from
# the ones the peer tests use.
GATEWAY_DDS_DOMAIN = 31
GATEWAY_LCM_URL = "udpm://239.255.76.67:7931?ttl=0"
GATEWAY_YAML = f"""gateway: {{name: py-gw}}
segments:
  - {{name: lan, type: dds, domain: {GATEWAY_DDS_DOMAIN}, latency_bound: 2ms}}
  - {{name: viz, type: lcm, url: "{GATEWAY_LCM_URL}", latency_bound: 2ms}}
channels:
  - {{name: py_range, subject: 0x2301, class: nrt, payload: 16B, omission_degree: 3, publishers: [viz], subscribers: [lan]}}
  - {{name: py_command, subject: 0x2302, class: nrt, payload: 16B, omission_degree: 3, publishers: [lan], subscribers: [viz]}}
"""


def wait_until(condition: Callable[[], bool], timeout: float, what: str, step: Optional[Callable[[], None]] = None) -> None:
    """Polls `condition` (running `step` before each poll) until it holds; fails after `timeout` s."""
    deadline = time.monotonic() + timeout
    while True:
        if step:
            step()
        if condition():
            return
        if time.monotonic() > deadline:
            pytest.fail(f"timed out after {timeout} s waiting for: {what}")
        time.sleep(0.01)


class Peer:
    """cosmic-client-peer in the background; READY on its stdout once its channels are announced."""

    def __init__(self, *args: str) -> None:
        self.process = subprocess.Popen([PEER, *args], stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                        text=True)
        line = self.process.stdout.readline()  # READY, or EOF when it failed
        if line.strip() != "READY":
            self.process.kill()
            pytest.fail(f"cosmic-client-peer {' '.join(args)} did not start: {self.process.stderr.read()}")

    def stop(self) -> str:
        """Closes its stdin (the echo mode ends there), waits for it and returns what it printed."""
        if not self.process.stdin.closed:
            self.process.stdin.close()
        try:
            self.process.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()
        return self.process.stdout.read()


@pytest.fixture
def peer() -> Iterator[Callable[..., Peer]]:
    started: list[Peer] = []

    def start(*args: str) -> Peer:
        started.append(Peer(*args))
        return started[-1]

    yield start
    for p in started:
        p.stop()


class Gateway:
    """cosmicd on `config` in `work`, with a state file that outlives restarts (stop(), start())."""

    def __init__(self, work: Path, config: str = GATEWAY_YAML) -> None:
        self.work = work
        self.socket = str(work / "control.sock")
        (work / "gateway.yaml").write_text(config)
        self.log_path = work / "cosmicd.log"
        self.process: Optional[subprocess.Popen] = None
        self.start()

    def start(self) -> None:
        self.log = open(self.log_path, "a")
        self.process = subprocess.Popen(
            [COSMICD, "--config", str(self.work / "gateway.yaml"), "--socket", self.socket, "--state-file", str(self.work / "state")],
            stdout=self.log, stderr=subprocess.STDOUT)
        wait_until(lambda: self.ctl("status").returncode == 0 or self.process.poll() is not None, 30, "cosmicd answering")
        if self.process.poll() is not None:
            pytest.fail(f"cosmicd exited: {self.log_path.read_text()}")

    def ctl(self, *args: str) -> subprocess.CompletedProcess:
        return subprocess.run([COSMICCTL, "--socket", self.socket, *args], capture_output=True, text=True)

    def stop(self) -> None:
        self.process.terminate()
        self.process.wait(timeout=20)
        self.log.close()

    def print_log_if_it_failed(self) -> None:
        if self.process.returncode not in (0, -15):
            print(self.log_path.read_text(), file=sys.stderr)


@pytest.fixture(scope="session")
def gateway() -> Iterator[Gateway]:
    with tempfile.TemporaryDirectory(prefix="cosmic-py-") as work:
        g = Gateway(Path(work))
        yield g
        g.stop()
        g.print_log_if_it_failed()