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

from autograder.core.errors import GraderError
from autograder.i18n import _

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
                  running: Callable[[], bool], timeout: float,
                  waited: Callable[[], float] = lambda: 0.0,
                  listening: Callable[[], bool] | None = None) -> dict[bytes, str]:
    """Wait, with simulation time held, until node ``name`` (any node: None) has publishers
    not in ``stale``, the program stops ``running``, or ``timeout`` seconds pass (the
    start-up is the machine's business: imports, discovery). The new publishers, if any.

    The seconds the program spent ``waited`` for a CPU (a busy machine's doing) do not
    count, so a start-up's verdict does not depend on the load; a program starved for
    :data:`STARVED_FACTOR` times ``timeout`` raises :class:`Starved`, the grader's failure.
    A start-up thus costs the same simulation time on any machine, and the node's first
    tick is the one after this returns.

    With ``listening`` (whether the world's /clock has matched the node's subscription),
    the hold goes on once the node is up until it holds, for at most LISTEN_GRACE of the
    program's time: a tick sent before that match is lost to the node, whose clock would
    then begin at a later tick, as late as the machine is slow."""
    started, waited_before = time.monotonic(), waited()
    cap = started + timeout * STARVED_FACTOR
    stale = set(stale)
    found: dict[bytes, str] = {}
    starved = False
    up: float | None = None  # the program's time (not counting its waits) when it was up

    def ready() -> bool:
        nonlocal found, starved, up
        found = {gid: node for gid, node in node_endpoints(graph, name).items()
                 if gid not in stale}
        now = time.monotonic()
        starved = now > cap
        took = now - started - (waited() - waited_before)
        if found and listening is not None and running() and not starved:
            up = took if up is None else up
            return listening() or took - up > LISTEN_GRACE
        return bool(found) or not running() or starved or took > timeout

    with world.held():
        world.wait_for(ready, sim_timeout=math.inf, wall_timeout=timeout * STARVED_FACTOR + 1)
    if starved and not found and running():
        raise Starved(timeout * STARVED_FACTOR, waited() - waited_before)
    return found


STARVED_FACTOR = 4
"""A start-up may take this many times its timeout in wall time while the machine keeps
the program waiting for a CPU."""
LISTEN_GRACE = 2.0
"""Seconds of the program's own time (not its waits for a CPU) that a node found on the graph
is given for its /clock subscription to match the world's publisher: the two are announced
together, so only a node that never listens to /clock (use_sim_time set false) waits it out."""


class Starved(GraderError):
    """The machine kept a starting program waiting for a CPU too long to judge its
    start-up: the grader's failure, never the student's."""

    def __init__(self, seconds: float, waited: float) -> None:
        super().__init__(_("The machine was too busy to judge the start-up: in {seconds:.0f} s "
                           "the program waited {waited:.0f} s for a CPU. Grade again on a "
                           "quieter machine.").format(seconds=seconds, waited=waited))
