"""A replacement under traffic (issue 23, items 2 and 5): `cosmicctl bind --replace` moves one
publisher segment of a channel while events flow, through a real cosmicd of its own on LCM and DDS.

Channel `feed` has two publishers and one subscriber. `steady` (LCM) publishes all along and is in
every definition; the other publisher segment is switched from `wire` (LCM) to `sim` (DDS) and
back. A redundant source sends every event of its stream on both `wire` and `sim` with the same
number, so the subscriber on `out` (DDS) sees which numbers crossed each switch and which did not.
The gateway promises, and the test asserts, that a subscriber that stays loses nothing of a
publisher that stays: its DDS writer and the `steady` subscription are kept, events already queued
go out. For the switched source it prints what was lost or delivered twice and how long the stream
paused, and asserts that the switch to the DDS publisher was made before break (it waited for the
match, so the pause is not DDS discovery); the figures are in docs/control-protocol.md (`replace`).
"""
from __future__ import annotations

import json
import struct
import subprocess
import tempfile
import threading
import time
from pathlib import Path
from typing import Iterator

import pytest

import cosmic
from conftest import Gateway, wait_until

STEADY_URL = "udpm://239.255.76.67:7951?ttl=0"
WIRE_URL = "udpm://239.255.76.67:7952?ttl=0"
SIM_DOMAIN = 52
OUT_DOMAIN = 53
RATE_HZ = 200
FEED = cosmic.ChannelDesc("feed", 0x2351, cls="srt", period=0.001, reaction_time=0.1, omission_degree=3, payload=16)
EVENT = struct.Struct("<B3xId")  # source tag, sequence number, send time (monotonic s)


def feed_yaml(*publishers: str, cls: str = "srt") -> str:
    return (f"{{name: feed, subject: 0x2351, class: {cls}, period: 1ms, reaction_time: 100ms, omission_degree: 3, "
            f"payload: 16B, publishers: [{', '.join(publishers)}], subscribers: [out]}}\n")


# The publisher segments' latency bound is what a time-shared Python publisher and cosmicd's own
# receive thread may bunch events by on a loaded machine (CI runs this next to other suites): the
# gateway's rate policing lets through a bunch that fits the bound (issue 20, item 1), so what the
# test counts as lost is the gateway's doing, not a publisher outside its contract.
CONFIG = f"""gateway: {{name: replace-gw}}
segments:
  - {{name: steady, type: lcm, url: "{STEADY_URL}", latency_bound: 30ms}}
  - {{name: wire, type: lcm, url: "{WIRE_URL}", latency_bound: 30ms}}
  - {{name: sim, type: dds, domain: {SIM_DOMAIN}, latency_bound: 30ms}}
  - {{name: out, type: dds, domain: {OUT_DOMAIN}, latency_bound: 2ms}}
channels:
  - {feed_yaml("steady", "wire")}"""


class OwnGateway(Gateway):
    """cosmicd on CONFIG (conftest.Gateway), with what the replacement tests ask of it."""

    def __init__(self, work: Path) -> None:
        super().__init__(work, CONFIG)

    def replace(self, yaml: str, name: str) -> tuple[subprocess.CompletedProcess, float]:
        path = self.work / name
        path.write_text(yaml)
        began = time.monotonic()
        done = self.ctl("bind", "--replace", str(path))
        return done, time.monotonic() - began

    def publishers(self) -> list[str]:
        answer = json.loads(self.ctl("--json", "channel", "feed").stdout)
        return [s["segment"] for s in answer["channel"]["segments"] if s["role"] == "publisher"]


@pytest.fixture
def own_gateway() -> Iterator[OwnGateway]:
    with tempfile.TemporaryDirectory(prefix="cosmic-replace-") as work:
        g = OwnGateway(Path(work))
        yield g
        g.stop()
        g.print_log_if_it_failed()


class Sources:
    """Two paced streams: `s` on steady alone, and one redundant stream whose event k goes out on
    wire (tag `w`) and on sim (tag `d`) with the same k."""

    def __init__(self, steady: cosmic.Channel, wire: cosmic.Channel, sim: cosmic.Channel) -> None:
        self.channels = (steady, wire, sim)
        self.sent = 0
        self.running = True
        self.thread = threading.Thread(target=self.run, daemon=True)
        self.thread.start()

    def run(self) -> None:
        steady, wire, sim = self.channels
        next_at = time.monotonic()
        while self.running:
            self.sent += 1
            now = time.monotonic()
            steady.publish(EVENT.pack(ord("s"), self.sent, now))
            wire.publish(EVENT.pack(ord("w"), self.sent, now))
            sim.publish(EVENT.pack(ord("d"), self.sent, now))
            next_at += 1 / RATE_HZ
            time.sleep(max(0.0, next_at - time.monotonic()))

    def stop(self) -> None:
        self.running = False
        self.thread.join(timeout=5)


class Received:
    def __init__(self) -> None:
        self.lock = threading.Lock()
        self.events: list[tuple[str, int, float, float]] = []  # tag, sequence, sent, received

    def __call__(self, event: cosmic.Event) -> None:
        tag, sequence, sent = EVENT.unpack(event.payload)
        with self.lock:
            self.events.append((chr(tag), sequence, sent, time.monotonic()))

    def of(self, tags: str) -> list[tuple[str, int, float, float]]:
        with self.lock:
            return [e for e in self.events if e[0] in tags]


def switch_figures(events: list[tuple[str, int, float, float]], before: str, after: str, window: tuple[float, float]) -> dict:
    """The redundant stream around one switch, from the events received in `window` (which holds
    that switch alone): the last number `before` delivered, the first `after` did, how many
    numbers between them neither delivered (lost), how many both did (twice), and the pause at
    the subscriber between those two events (negative: they overlapped)."""
    inside = [e for e in events if window[0] <= e[3] < window[1]]
    last_before = max((e for e in inside if e[0] == before), key=lambda e: e[1])
    first_after = min((e for e in inside if e[0] == after), key=lambda e: e[1])
    numbers = {e[1] for e in inside}
    low, high = min(last_before[1], first_after[1]), max(last_before[1], first_after[1])
    twice = {e[1] for e in inside if e[0] == before} & {e[1] for e in inside if e[0] == after}
    return {"last_before": last_before[1], "first_after": first_after[1],
            "lost": sum(1 for k in range(low, high + 1) if k not in numbers), "twice": len(twice),
            "pause_ms": round((first_after[3] - last_before[3]) * 1e3, 1)}


def steady_figures(events: list[tuple[str, int, float, float]]) -> dict:
    numbers = sorted(e[1] for e in events)
    first, last = numbers[0], numbers[-1]
    gaps = [(b[3] - a[3]) * 1e3 for a, b in zip(events, events[1:])]
    return {"first": first, "last": last, "lost": (last - first + 1) - len(set(numbers)), "twice": len(numbers) - len(set(numbers)),
            "max_gap_ms": round(max(gaps), 1), "latency_max_ms": round(max(e[3] - e[2] for e in events) * 1e3, 1)}


def steady_rate_drops(g: OwnGateway) -> int:
    """The `rate` drops of feed's events from steady under the current route (cosmicctl channel)."""
    channel = json.loads(g.ctl("--json", "channel", "feed").stdout)["channel"]
    return sum(seg["dropped"].get("rate", 0) for seg in channel["segments"] if seg["segment"] == "steady")


def test_a_replacement_under_traffic_keeps_the_subscriber_that_stays(own_gateway):
    g = own_gateway
    with cosmic.Client(f"lcm:{STEADY_URL}") as steady_c, cosmic.Client(f"lcm:{WIRE_URL}") as wire_c, \
            cosmic.Client(f"dds:{SIM_DOMAIN}") as sim_c, cosmic.Client(f"dds:{OUT_DOMAIN}") as out_c:
        received = Received()
        out_c.announce(FEED, roles=cosmic.SUBSCRIBE).subscribe(received)
        sources = Sources(*(c.announce(FEED, roles=cosmic.PUBLISH) for c in (steady_c, wire_c, sim_c)))
        try:
            wait_until(lambda: received.of("s") and received.of("w"), 30, "the gateway's DDS writer on out matched")
            time.sleep(0.5)
            start = received.of("s")[-1][1]
            # Rate policing drops of steady's events, per route (a replacement starts the channel's
            # counters afresh): what a publisher bunching beyond its latency bound on a loaded
            # machine loses by its own doing, told apart from what the gateway loses.
            policed = [-steady_rate_drops(g)]

            # A replacement admission rejects (HRT over segments without a real-time guarantee):
            # nothing changes, traffic goes on as before.
            rejected, _ = g.replace(feed_yaml("steady", "sim", cls="hrt"), "rejected.yaml")
            assert rejected.returncode == 1, rejected.stdout + rejected.stderr
            assert "rejected" in rejected.stdout + rejected.stderr
            assert g.publishers() == ["steady", "wire"]
            unbound, _ = g.replace("{name: fed, subject: 0x2352, class: nrt, publishers: [steady], subscribers: [out]}\n", "typo.yaml")
            assert unbound.returncode != 0 and "no bound channel named 'fed' to replace" in unbound.stderr, unbound.stderr
            time.sleep(0.3)

            policed.append(steady_rate_drops(g))
            first_switch = time.monotonic()
            to_sim, took_to_sim = g.replace(feed_yaml("steady", "sim"), "to-sim.yaml")
            assert to_sim.returncode == 0, to_sim.stdout + to_sim.stderr
            switched_to_sim = time.monotonic()
            assert "publishers: [steady, wire] -> [steady, sim]" in to_sim.stdout
            assert "hops kept: steady (P), out (S); added: sim (P); removed: wire (P)" in to_sim.stdout, to_sim.stdout
            # Made before break: the switch waited for sim's writer to match the gateway's new reader.
            assert "new publisher sim of feed: 1 writer(s) matched before the switch" in to_sim.stdout, to_sim.stdout
            wait_until(lambda: any(e[3] > switched_to_sim for e in received.of("d")), 15, "events from sim after the switch")
            time.sleep(0.5)

            policed.append(steady_rate_drops(g))
            second_switch = time.monotonic()
            to_wire, took_to_wire = g.replace(feed_yaml("steady", "wire"), "to-wire.yaml")
            assert to_wire.returncode == 0, to_wire.stdout + to_wire.stderr
            switched_to_wire = time.monotonic()
            wait_until(lambda: any(e[3] > switched_to_wire for e in received.of("w")), 15, "events from wire after the switch")
            time.sleep(0.5)
        finally:
            sources.stop()
        time.sleep(0.3)  # the last events in flight

        policed.append(steady_rate_drops(g))
        steady = [e for e in received.of("s") if e[1] >= start]
        figures = steady_figures(steady)
        to_sim_figures = switch_figures(received.of("wd"), "w", "d", (first_switch - 0.3, second_switch))
        to_wire_figures = switch_figures(received.of("wd"), "d", "w", (second_switch - 0.3, time.monotonic()))
        channel = json.loads(g.ctl("--json", "channel", "feed").stdout)["channel"]
        counters = {s["segment"]: {"rx": s["rx"], "tx": s["tx"], "dropped": {k: v for k, v in s["dropped"].items() if v}}
                    for s in channel["segments"]}
        print(f"\ncosmicd's counters of feed since the last replacement: forwarded {channel.get('forwarded')}, {counters}")
        print(f"\nreplacement under traffic, {RATE_HZ} events/s per stream:"
              f"\n  publisher that stays (steady, LCM) -> subscriber that stays (out, DDS): {figures}"
              f"\n  wire (LCM) -> sim (DDS), `cosmicctl bind --replace` took {took_to_sim * 1e3:.0f} ms: {to_sim_figures}"
              f"\n  sim (DDS) -> wire (LCM), `cosmicctl bind --replace` took {took_to_wire * 1e3:.0f} ms: {to_wire_figures}")
        # The promise: a subscriber that stays misses nothing of a publisher that stays, across a
        # rejected replacement and two switches (figures["first"] is before all three), but what the
        # gateway's rate policing dropped of a publisher that bunched its events beyond its latency
        # bound (counted as `rate`, printed here).
        policed_total = sum(policed)
        print(f"  steady's events dropped by rate policing (publisher beyond its contract): {policed_total}")
        assert figures["twice"] == 0, figures
        assert figures["lost"] <= policed_total, (figures, policed)
        assert figures["last"] > to_wire_figures["first_after"]
        # The switched source's pause is what was in flight on the hop removed, not DDS discovery
        # (seconds on a loaded machine before the switch was made before break, issue 40).
        assert to_sim_figures["pause_ms"] < 1000, to_sim_figures

    # Persisted like bind: after a restart the channel has the last replacement's definition.
    assert g.replace(feed_yaml("steady", "sim"), "to-sim-again.yaml")[0].returncode == 0
    g.stop()
    g.start()
    assert g.publishers() == ["steady", "sim"]
    state = json.loads((g.work / "state").read_text())
    assert [b["name"] for b in state["bound"]] == ["feed"] and state["unbound"] == ["feed"], state
    # Back to the file's definition: nothing runtime is left to restore.
    assert g.replace(feed_yaml("steady", "wire"), "back.yaml")[0].returncode == 0
    assert json.loads((g.work / "state").read_text())["bound"] == []
    g.stop()
    g.start()
    assert g.publishers() == ["steady", "wire"]
