"""get_event(): polling as a fixed-step tool does (Fig. 9), timeouts, and waiting without the GIL."""
from __future__ import annotations

import os
import threading
import time

import pytest

import cosmic
from conftest import wait_until

LCM = "lcm:udpm://239.255.76.67:7971?ttl=0"


@pytest.fixture
def pair():
    with cosmic.Client(LCM) as a, cosmic.Client(LCM) as b:
        yield (a.announce("py_poll", 0x2331, payload=8, roles="publish"),
               b.announce("py_poll", 0x2331, payload=8, roles="subscribe"))


def test_timeouts(pair):
    out, into = pair
    start = time.monotonic()
    assert into.get_event() is None  # default timeout 0: a poll, no waiting
    assert into.get_event(timeout=0) is None
    assert time.monotonic() - start < 0.1
    start = time.monotonic()
    assert into.get_event(timeout=0.3) is None
    assert 0.3 <= time.monotonic() - start < 3
    # An event published while get_event() waits ends the wait early.
    later = threading.Timer(0.2, lambda: out.publish(b"late"))
    later.start()
    start = time.monotonic()
    event = into.get_event(timeout=20)
    assert event is not None and event.payload == b"late" and time.monotonic() - start < 10
    # timeout=None, or one too long to matter, waits as long as it takes.
    threading.Timer(0.2, lambda: out.publish(b"later")).start()
    assert into.get_event(timeout=None).payload == b"later"
    threading.Timer(0.2, lambda: out.publish(b"last")).start()
    assert into.get_event(timeout=1e300).payload == b"last"


def test_other_threads_run_while_get_event_waits(pair):
    _, into = pair
    ticks = 0
    stop = threading.Event()

    def count() -> None:
        nonlocal ticks
        while not stop.is_set():
            ticks += 1

    counter = threading.Thread(target=count)
    counter.start()
    time.sleep(0.05)
    before = ticks
    into.get_event(timeout=0.5)  # releases the GIL: the counting thread keeps running
    during = ticks - before
    stop.set()
    counter.join()
    assert during > 1000, f"the counting thread advanced only {during} times while get_event() waited"


def test_closing_the_client_ends_a_wait():
    client = cosmic.Client(LCM)
    into = client.announce("py_poll_close", 0x2332, payload=8, roles="subscribe")
    outcome: list[BaseException] = []

    def wait() -> None:
        try:
            into.get_event(timeout=None)
        except cosmic.ClosedError as e:
            outcome.append(e)

    waiter = threading.Thread(target=wait)
    waiter.start()
    time.sleep(0.1)  # let it wait (the test's pass criterion is the join below)
    client.close()
    waiter.join(timeout=10)
    assert not waiter.is_alive() and len(outcome) == 1


def test_a_fixed_step_loop_polls_every_event(pair):
    """A 200 Hz simulation loop polls once per step while another thread publishes at ~100 Hz:
    every event reaches the loop, in order, none lost (the queue keeps the newest 64)."""
    out, into = pair
    published = [k.to_bytes(8, "little") for k in range(100)]

    def publish() -> None:
        for payload in published:
            out.publish(payload)
            time.sleep(0.01)

    publisher = threading.Thread(target=publish)
    publisher.start()
    received: list[bytes] = []
    step = 0.005
    next_step = time.monotonic()
    deadline = next_step + 30
    while len(received) < len(published) and time.monotonic() < deadline:
        while (event := into.get_event()) is not None:  # what arrived since the last step
            received.append(event.payload)
        next_step += step
        time.sleep(max(0.0, next_step - time.monotonic()))
    publisher.join()
    assert received == published


def test_subscribe_and_unsubscribe_switch_between_callback_and_queue(pair):
    out, into = pair
    out.publish(b"queued")
    wait_until(lambda: (e := into.get_event(timeout=0.1)) is not None and e.payload == b"queued", 10, "the queued event")
    got: list[bytes] = []
    into.subscribe(lambda e: got.append(e.payload))
    wait_until(lambda: b"callback" in got, 10, "the callback", step=lambda: out.publish(b"callback"))
    into.unsubscribe()
    out.publish(b"again")  # after unsubscribe() events are queued for get_event() again
    wait_until(lambda: (e := into.get_event(timeout=0.1)) is not None and e.payload == b"again", 10, "a queued event")


def test_the_last_reference_dropped_inside_a_callback_closes_the_client():
    """The client's last reference goes inside its own callback, on the receive thread that
    cosmic_close() joins: it is closed from another thread once the callback returned, and its
    threads end (a self-join would leave them hanging)."""
    def threads() -> int:
        return len(os.listdir("/proc/self/task"))

    with cosmic.Client(LCM) as publisher:
        out = publisher.announce("py_poll_last", 0x2333, payload=8, roles="publish")
        before = threads()
        done = threading.Event()
        holder = {}
        client = cosmic.Client(LCM)
        holder["channel"] = client.announce("py_poll_last", 0x2333, payload=8, roles="subscribe")

        def callback(event: cosmic.Event) -> None:
            holder.clear()  # the Channel, and with it the client, go here
            done.set()

        holder["channel"].subscribe(callback)
        del client
        assert threads() > before
        wait_until(done.is_set, 10, "the callback ran", step=lambda: out.publish(b"x"))
        wait_until(lambda: threads() == before, 10, "the client's threads ended")
        # The process carries on: a new client on the same group works.
        with cosmic.Client(LCM) as again:
            into = again.announce("py_poll_last", 0x2333, payload=8, roles="subscribe")
            wait_until(lambda: into.get_event(timeout=0.05) is not None, 10, "an event", step=lambda: out.publish(b"y"))
