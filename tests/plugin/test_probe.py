"""The probe's Inbox: what it keeps of a flood, and its waits on arrivals (no ROS needed)."""

from __future__ import annotations

import threading

from autograder.plugin.probe import Inbox


def test_a_flood_is_counted_not_kept(monkeypatch):
    monkeypatch.setattr(Inbox, "LIMIT", 3)
    inbox: Inbox[int] = Inbox("/cmd_vel")
    for i in range(5):
        inbox.add(float(i), i)
    assert inbox.messages == [0, 1, 2]
    assert inbox.dropped == 2


def test_each_message_keeps_the_wall_time_it_was_sent_at_beside_its_stamp(monkeypatch):
    """A kept message's source time stays paired with its sim stamp, a flood's dropped
    ones take none, and clear() forgets both."""
    monkeypatch.setattr(Inbox, "LIMIT", 2)
    inbox: Inbox[str] = Inbox("/cmd_vel")
    inbox.add(1.0, "a", 100.25)
    inbox.add(1.1, "b")
    inbox.add(1.2, "c", 100.45)
    assert inbox.sent == [(1.0, 100.25), (1.1, None)]
    inbox.clear()
    assert inbox.sent == [] and len(inbox) == 0


def test_wait_until_wakes_on_the_arrival_that_makes_it_true():
    inbox: Inbox[str] = Inbox("/cmd_vel")
    sender = threading.Thread(target=lambda: [inbox.add(0.0, "go"), inbox.add(0.1, "stop")])
    sender.start()
    assert inbox.wait_until(lambda: inbox.messages[-1:] == ["stop"], wall_timeout=10.0)
    sender.join()


def test_wait_until_gives_up_at_its_deadline():
    inbox: Inbox[str] = Inbox("/cmd_vel")
    inbox.add(0.0, "go")
    assert not inbox.wait_until(lambda: inbox.messages[-1] == "stop", wall_timeout=0.05)


def test_wait_quiet_returns_once_nothing_arrives():
    inbox: Inbox[int] = Inbox("/cmd_vel")
    inbox.add(0.0, 1)
    assert inbox.wait_quiet(quiet=0.02, limit=5.0)


def test_wait_quiet_waits_while_a_message_is_still_on_its_way():
    """Nothing arriving for a while is not enough while what delivers still has work (a
    crowded machine can leave the probe's executor without a CPU for longer than any quiet
    spell): the late message is in when the wait returns."""
    inbox: Inbox[int] = Inbox("/cmd_vel")
    inbox.add(0.0, 1)
    on_its_way, go = threading.Event(), threading.Event()
    on_its_way.set()
    asked = []

    def delivering() -> bool:
        asked.append(on_its_way.is_set())
        if len(asked) == 3:  # asked after quiet spells: only now does it come
            go.set()
        return on_its_way.is_set()

    def deliver() -> None:
        go.wait()
        inbox.add(0.0, 2)
        on_its_way.clear()

    deliverer = threading.Thread(target=deliver)
    deliverer.start()
    try:
        assert inbox.wait_quiet(quiet=0.01, limit=30.0, delivering=delivering)
    finally:
        go.set()
        deliverer.join()
    assert inbox.messages == [1, 2]
    assert asked[:3] == [True, True, True] and asked[-2:] == [False, False]


def test_wait_quiet_ends_at_its_limit_however_long_delivery_seems_busy():
    """A student who keeps the grader's middleware busy (a flood on the graph) keeps
    delivering() True: the wait still ends at its limit, as under a flood into the inbox."""
    inbox: Inbox[int] = Inbox("/cmd_vel")
    assert not inbox.wait_quiet(quiet=0.01, limit=0.2, delivering=lambda: True)


def test_wait_quiet_is_not_fooled_by_a_flood_even_past_the_limit(monkeypatch):
    monkeypatch.setattr(Inbox, "LIMIT", 10)  # dropped messages still count as arrivals
    inbox: Inbox[int] = Inbox("/cmd_vel")
    done = threading.Event()

    def flood() -> None:
        while not done.is_set():
            inbox.add(0.0, 0)

    flooder = threading.Thread(target=flood)
    flooder.start()
    try:
        assert not inbox.wait_quiet(quiet=0.2, limit=0.6)
    finally:
        done.set()
        flooder.join()
    assert inbox.dropped > 0


def test_iterating_an_inbox_gives_its_messages_as_they_stand():
    """`for msg in inbox` works as an instructor first writes it (issue 33: an Inbox was
    not iterable): a snapshot of the messages, which later arrivals do not change."""
    inbox: Inbox[str] = Inbox("/greeting")
    inbox.add(0.5, "Hello, Ada!")
    inbox.add(0.7, "Hello, Alan!")
    snapshot = iter(inbox)
    inbox.add(0.9, "Hello, Grace!")
    assert list(snapshot) == ["Hello, Ada!", "Hello, Alan!"]
    assert list(inbox) == inbox.messages and len(list(inbox)) == len(inbox) == 3
