"""How the grader waits for a student's node to start (graph and world stood in by fakes).

A restarted program's node has the name of the instance before it, which lingers on the
graph (a killed process stays listed until its DDS lease runs out, and the name can outlive
the instance's endpoints): only publishers the graph did not show before the start may
count as the new instance's, and a name alone never does.
"""

from __future__ import annotations

import contextlib
import dataclasses
from collections.abc import Callable, Iterator
from types import SimpleNamespace

from autograder.plugin.student import StudentNode, _node_endpoints, _wait_for_node

NAME = "obstacle_avoider"


@dataclasses.dataclass
class Info:
    node_name: str
    endpoint_gid: bytes


class Graph:
    """What the probe's node sees; ``later`` joins after ``delay`` of the world's checks."""

    def __init__(self, now: list[Info], later: list[Info] = (), delay: int = 0,
                 lingering: set[str] = frozenset()) -> None:
        self.now, self.later, self.delay, self.looks = list(now), list(later), delay, 0
        self.lingering = set(lingering)  # names listed without any endpoint

    def get_publishers_info_by_topic(self, topic: str) -> list[Info]:
        return list(self.now)

    def look(self) -> None:
        self.looks += 1
        if self.looks > self.delay:
            self.now += self.later
            self.later = []

    def names(self) -> set[str]:
        return ({info.node_name for info in self.now} | self.lingering
                | {"sim_world", "autograder_probe"})


class World:
    def __init__(self, graph: Graph) -> None:
        self.graph = graph
        self.now = 12.5  # sim time: it stands still while the node starts
        self.holding = False
        self.held_while_waiting: list[bool] = []

    @contextlib.contextmanager
    def held(self) -> Iterator[None]:
        self.holding = True
        try:
            yield
        finally:
            self.holding = False

    def wait_for(self, predicate: Callable[[], bool], sim_timeout: float,
                 wall_timeout: float) -> bool:
        for _ in range(1000):
            self.graph.look()
            self.held_while_waiting.append(self.holding)
            if predicate():
                return True
        return False


def start(graph: Graph, world: World, stale: set[bytes]) -> StudentNode:
    probe = SimpleNamespace(node=graph, node_names=graph.names, world=world)
    process = SimpleNamespace(running=lambda: True, started_at=0.0, returncode=None, pid=0)
    node = StudentNode(process, NAME, probe)
    exercise = SimpleNamespace(node=NAME, startup_timeout=20.0, file="obstacle_avoider.py")
    _wait_for_node(exercise, node, world, stale)
    return node


def test_a_restart_waits_for_the_new_instance_not_the_lingering_one():
    old, new = Info(NAME, b"old"), Info(NAME, b"new")
    graph = Graph([old], [new], delay=5)
    world = World(graph)
    stale = _node_endpoints(SimpleNamespace(node=graph), NAME)
    assert stale == {b"old"}
    start(graph, world, stale)
    assert len(world.held_while_waiting) == 6  # not before the new instance showed
    assert all(world.held_while_waiting) and not world.holding


def test_a_lingering_name_without_endpoints_is_not_the_new_instance():
    # Seen in a stress run: the earlier instance's endpoints were gone, its name was not,
    # and a wait that took the name found the node 2 ms after the start.
    graph = Graph([], [Info(NAME, b"new")], delay=3, lingering={NAME})
    world = World(graph)
    stale = _node_endpoints(SimpleNamespace(node=graph), NAME)
    assert stale == set() and NAME in graph.names()
    start(graph, world, stale)
    assert len(world.held_while_waiting) == 4  # the look that showed the new publishers
    assert all(world.held_while_waiting) and not world.holding


def test_a_first_start_is_done_when_its_publishers_appear():
    graph = Graph([], [Info(NAME, b"first")], delay=2)
    world = World(graph)
    node = start(graph, world, stale=set())
    assert len(world.held_while_waiting) == 3  # done on the look that found it
    assert node.startup_seconds is not None
    assert node.appeared_at == 12.5  # its timers began then (timer_sync's run counts from it)
    assert all(world.held_while_waiting) and not world.holding


def test_other_nodes_publishers_are_not_the_students():
    graph = Graph([Info("sim_world", b"w"), Info(NAME, b"a"), Info("talker", b"t")])
    assert _node_endpoints(SimpleNamespace(node=graph), NAME) == {b"a"}


class Clock:
    """Wall time that moves one second per look at the graph."""

    def __init__(self, graph: Graph) -> None:
        self.graph, self.start = graph, 1000.0

    def __call__(self) -> float:
        return self.start + self.graph.looks


def test_time_spent_waiting_for_a_cpu_does_not_count_toward_the_start_up(monkeypatch):
    """A busy machine keeps the program waiting for a CPU 0.9 s of every second: its node
    shows after 30 s of wall time, 3 s of its own, within a 10 s start-up."""
    from autograder.plugin import graph as graph_module

    graph = Graph([], [Info(NAME, b"new")], delay=30)
    monkeypatch.setattr(graph_module.time, "monotonic", Clock(graph))
    found = graph_module.wait_until_up(World(graph), graph, NAME, set(), lambda: True, 10.0,
                                       lambda: 0.9 * graph.looks)
    assert found == {b"new": NAME}
    graph = Graph([], [Info(NAME, b"new")], delay=30)  # on a quiet machine: given up at 10 s
    monkeypatch.setattr(graph_module.time, "monotonic", Clock(graph))
    assert graph_module.wait_until_up(World(graph), graph, NAME, set(), lambda: True,
                                      10.0) == {}
    assert graph.looks == 11


def test_a_start_up_starved_past_its_cap_is_the_graders_failure(monkeypatch):
    from autograder.core.errors import GraderError
    from autograder.plugin import graph as graph_module

    graph = Graph([], [Info(NAME, b"new")], delay=500)
    monkeypatch.setattr(graph_module.time, "monotonic", Clock(graph))
    try:
        graph_module.wait_until_up(World(graph), graph, NAME, set(), lambda: True, 10.0,
                                   lambda: float(graph.looks))  # it never got a CPU
    except graph_module.Starved as exc:
        assert isinstance(exc, GraderError) and "too busy" in str(exc)
    else:
        raise AssertionError("a starved start-up was judged")
    assert graph.looks == 41  # 4 x 10 s of wall time
