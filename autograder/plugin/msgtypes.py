"""Message types that never match: the student's node publishes or subscribes a type other
than the grader's on the same topic (``TwistStamped`` where the robot takes ``Twist``).

DDS never connects such endpoints and nothing says so: the node would just lose points
for "nothing on cmd_vel".  The probe watches the graph (:class:`TypeWatch`, every
``CHECK_EVERY`` of sim time and when a test fails) and the reporter puts what it saw, once,
before the message of every test that failed, setup failures of module fixtures included.
"""

from __future__ import annotations

import threading
from typing import TYPE_CHECKING

import pytest

from autograder.i18n import _
from autograder.plugin.stash import type_watch_key
from sim.cmdvel import CMD_VEL_TOPIC, Mismatch, full_name, mismatches, short

if TYPE_CHECKING:
    from rclpy.node import Node

# Sim seconds between two looks at the graph while a test runs.
CHECK_EVERY = 0.25


class TypeWatch:
    """Endpoints of other nodes whose type differs from the grader's on the same topic:
    publishers where the world or the probe subscribes, subscriptions where they publish."""

    def __init__(self, node: Node, ignore: tuple[str, ...]) -> None:
        self.node = node
        self.ignore = ignore
        self.subscribed: dict[str, str] = {}  # topic -> full type the grader takes there
        self.published: dict[str, str] = {}   # topic -> full type the grader sends there
        self._seen: set[Mismatch] = set()
        self._lock = threading.Lock()
        self.closed = False

    def takes(self, topic: str, type_name: str) -> None:
        """The grader subscribes to ``topic`` with ``type_name`` (the world's own first)."""
        with self._lock:
            self.subscribed.setdefault(topic, type_name)

    def sends(self, topic: str, type_name: str) -> None:
        """The grader publishes ``type_name`` on ``topic``."""
        with self._lock:
            self.published.setdefault(topic, type_name)

    def check(self) -> None:
        """Look at the graph now; what was seen once stays seen (a node may exit later)."""
        with self._lock:
            if self.closed:
                return
            subscribed, published = dict(self.subscribed), dict(self.published)
        found = mismatches(self.node, subscribed, ignore=self.ignore) + mismatches(
            self.node, published, publishers=False, ignore=self.ignore)
        with self._lock:
            self._seen.update(found)

    def close(self) -> None:
        """The node is going: no more looks, what was seen stays."""
        with self._lock:
            self.closed = True

    @property
    def seen(self) -> list[Mismatch]:
        with self._lock:
            return sorted(self._seen)


def describe(mismatch: Mismatch) -> str:
    """One mismatch in words a student can act on."""
    values = {"node": mismatch.node, "topic": mismatch.topic, "found": mismatch.found,
              "expected": mismatch.expected, "short": short(mismatch.expected)}
    if not mismatch.publishes:
        return _("Your node '{node}' subscribes to {topic} as {found}, but {expected} is "
                 "published there, so its callback never runs: subscribe with {short}.").format(
            **values)
    if mismatch.topic == CMD_VEL_TOPIC:
        return _("Your node '{node}' publishes {found} on {topic}, but this exercise's robot "
                 "takes {expected} (its cmd_vel_type), so the robot never hears it: publish "
                 "{short}.").format(**values)
    return _("Your node '{node}' publishes {found} on {topic}, but the grader takes "
             "{expected} there, so nothing it publishes arrives: publish {short}.").format(
        **values)


def note(found: list[Mismatch]) -> str:
    """The paragraph a failing test's feedback starts with ("" when all types match)."""
    return "\n".join(describe(m) for m in found)


def watch_world_cmd_vel(watch: TypeWatch, cmd_vel_type: str | None) -> None:
    """The world takes ``cmd_vel_type`` on /cmd_vel."""
    if cmd_vel_type:
        watch.takes(CMD_VEL_TOPIC, full_name(cmd_vel_type))


def type_note(item: pytest.Item) -> str:
    """What the test module's probe saw of types that never match, after a last look (the
    paragraph a failed test's feedback starts with; "" when all types match)."""
    for node in reversed(item.listchain()):
        watch = node.stash.get(type_watch_key, None)
        if watch is not None:
            watch.check()
            return note(watch.seen)
    return ""
