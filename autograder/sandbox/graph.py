"""Whether a started program's node is up on the ROS graph: the start-up check that grading
(:mod:`autograder.plugin.student`) and a hand run (``autograder sim run --node``) share.

A node counts as up when it has publishers on NODE_TOPICS that the graph did not show
before the start. Its name alone is not enough: when a program is started again, the
name of the instance before lingers (a killed process stays listed until its DDS lease
runs out, and the name can outlive its endpoints).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Iterable
from contextlib import AbstractContextManager
from typing import Protocol

# Every rclpy node publishes on these (its log and its parameter events): the endpoints
# that tell one instance of a node from another of the same name.
NODE_TOPICS = ("/rosout", "/parameter_events")
# The name the graph gives an endpoint before its node's name is known.
UNKNOWN_NODE = "_NODE_NAME_UNKNOWN_"


class Graph(Protocol):
    """What of an rclpy node the check uses: the graph as that node sees it."""

    def get_publishers_info_by_topic(self, topic: str) -> Iterable:  # TopicEndpointInfo
        ...


class HeldWorld(Protocol):
    """What of :class:`sim.bridge.SimBridge` the check uses."""

    def held(self) -> AbstractContextManager[None]: ...

    def wait_for(self, predicate: Callable[[], bool], sim_timeout: float,
                 wall_timeout: float) -> bool: ...


def node_endpoints(graph: Graph, name: str | None) -> dict[bytes, str]:
    """The publishers node ``name`` (any node whose name is known: None) has on NODE_TOPICS,
    as the graph shows them: endpoint GID to node name."""
    return {bytes(info.endpoint_gid): info.node_name for topic in NODE_TOPICS
            for info in graph.get_publishers_info_by_topic(topic)
            if info.node_name == name or name is None and info.node_name != UNKNOWN_NODE}


def wait_until_up(world: HeldWorld, graph: Graph, name: str | None, stale: Iterable[bytes],
                  running: Callable[[], bool], timeout: float) -> dict[bytes, str]:
    """Wait, with simulation time held, until node ``name`` (any node: None) has publishers
    not in ``stale``, the program stops ``running``, or ``timeout`` wall seconds pass (the
    start-up is the machine's business: imports, discovery). The new publishers, if any.

    A start-up thus costs the same simulation time on any machine, and the node's first
    tick is the one after this returns."""
    deadline = time.monotonic() + timeout
    stale = set(stale)
    found: dict[bytes, str] = {}

    def ready() -> bool:
        nonlocal found
        found = {gid: node for gid, node in node_endpoints(graph, name).items()
                 if gid not in stale}
        return bool(found) or not running() or time.monotonic() > deadline

    with world.held():
        world.wait_for(ready, sim_timeout=math.inf, wall_timeout=timeout + 1)
    return found
