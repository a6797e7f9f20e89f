"""Callbacks under 10k events/s for a few seconds (from the C++ peer on LCM): no reference and no
memory is leaked per event, and a callback that raises neither kills the receive thread nor leaks."""
from __future__ import annotations

import gc
import sys
import threading
import time
import tracemalloc

import cosmic
from conftest import wait_until

LCM_URL = "udpm://239.255.76.67:7981?ttl=0"
CHANNEL = "py_flood:0x2341"


def rss_kib() -> int:
    with open("/proc/self/status") as status:
        return next(int(line.split()[1]) for line in status if line.startswith("VmRSS:"))


def flood(peer, count: int) -> None:
    p = peer("pub", "--segment", f"lcm:{LCM_URL}", "--channel", CHANNEL, "--payload", "16", "--count", str(count),
             "--rate", "10000")
    p.process.wait(timeout=60)
    out = p.stop()
    assert p.process.returncode == 0, out
    print("peer:", out.strip())


def test_callbacks_at_10k_events_per_second_leak_nothing(peer):
    with cosmic.Client(f"lcm:{LCM_URL}") as client:
        channel = client.announce("py_flood", 0x2341, payload=16, omission_degree=3, roles="subscribe")
        received = 0
        lock = threading.Lock()

        def on_event(event: cosmic.Event) -> None:
            nonlocal received
            assert len(event.payload) == 16
            with lock:
                received += 1

        refs_before = sys.getrefcount(on_event)
        channel.subscribe(on_event)
        flood(peer, 5000)  # warm-up: allocator pools, the receive thread's state
        gc.collect()
        tracemalloc.start()
        traced_before, _ = tracemalloc.get_traced_memory()
        rss_before = rss_kib()
        received = 0
        start = time.monotonic()
        flood(peer, 30000)  # 3 s at 10k/s
        took = time.monotonic() - start
        wait_until(lambda: received >= 30000 * 0.5, 10, "at least half of the flood delivered")
        time.sleep(0.2)  # the last datagrams in the socket (not a pass criterion)
        gc.collect()
        traced_after, _ = tracemalloc.get_traced_memory()
        tracemalloc.stop()
        rss_after = rss_kib()
        channel.unsubscribe()
        refs_after = sys.getrefcount(on_event)
        print(f"received {received} of 30000 in {took:.2f} s; traced memory {traced_after - traced_before:+d} B, "
              f"RSS {rss_after - rss_before:+d} KiB, callback references {refs_before} -> {refs_after}")
        assert refs_after == refs_before
        assert traced_after - traced_before < 256 * 1024  # a leak of one event each would be > 1 MB
        assert rss_after - rss_before < 32 * 1024


def test_a_callback_that_raises_is_reported_and_the_receive_thread_carries_on(peer):
    reported: list[type] = []
    previous_hook = sys.unraisablehook
    sys.unraisablehook = lambda unraisable: reported.append(unraisable.exc_type)
    try:
        with cosmic.Client(f"lcm:{LCM_URL}") as client:
            channel = client.announce("py_flood", 0x2341, payload=16, omission_degree=3, roles="subscribe")
            calls = 0

            def explode(event: cosmic.Event) -> None:
                nonlocal calls
                calls += 1
                raise ValueError(f"callback failure {calls}")

            refs_before = sys.getrefcount(explode)
            channel.subscribe(explode)
            flood(peer, 2000)
            wait_until(lambda: len(reported) >= 1000, 10, "the failures reported")
            assert set(reported) == {ValueError}
            # The receive thread is alive: a well-behaved callback gets the next events.
            fine: list[cosmic.Event] = []
            channel.subscribe(fine.append)
            assert sys.getrefcount(explode) == refs_before
            flood(peer, 500)
            wait_until(lambda: len(fine) >= 250, 10, "events after the failures")
    finally:
        sys.unraisablehook = previous_hook
