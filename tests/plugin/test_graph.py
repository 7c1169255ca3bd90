"""Whether a started program's node is up: publishers on the topics every node publishes
that the graph did not show before the start, waited for with simulation time held; the
seconds the program waited for a CPU do not count, and a start-up starved past its cap is
the grader's failure. (How grading uses it for a restarted node: tests/plugin/test_student.py.)"""

from __future__ import annotations

from graph_fakes import NAME, Clock, Graph, Info, World

from autograder.core.errors import GraderError
from autograder.plugin import graph as graph_module
from autograder.plugin.graph import NODE_TOPICS, UNKNOWN_NODE, node_endpoints, wait_until_up


class TopicGraph:
    """A graph with publishers per topic."""

    def __init__(self, by_topic: dict[str, list[Info]]) -> None:
        self.by_topic = by_topic

    def get_publishers_info_by_topic(self, topic: str) -> list[Info]:
        return self.by_topic.get(topic, [])


def test_a_nodes_endpoints_on_the_topics_every_node_publishes():
    graph = TopicGraph({
        "/rosout": [Info(NAME, b"log"), Info("sim_world", b"w"), Info(UNKNOWN_NODE, b"u")],
        "/parameter_events": [Info(NAME, b"params")],
        "/cmd_vel": [Info(NAME, b"drive")]})  # a topic of its own: not what tells instances
    assert NODE_TOPICS == ("/rosout", "/parameter_events")
    assert node_endpoints(graph, NAME) == {b"log": NAME, b"params": NAME}
    assert node_endpoints(graph, "talker") == {}
    # Any node whose name is known: not one the graph has no name for yet.
    assert node_endpoints(graph, None) == {b"log": NAME, b"w": "sim_world", b"params": NAME}


def test_new_publishers_found_with_the_world_held():
    graph = Graph([Info(NAME, b"old")], [Info(NAME, b"new"), Info("talker", b"t")], delay=2)
    world = World(graph)
    assert wait_until_up(world, graph, NAME, {b"old"}, lambda: True, 10.0) == {b"new": NAME}
    assert world.held_while_waiting == [True, True, True] and not world.holding
    graph = Graph([], [Info("talker", b"t")], delay=1)
    assert wait_until_up(World(graph), graph, None, set(), lambda: True, 10.0) == \
        {b"t": "talker"}


def test_a_program_that_ended_is_not_waited_for():
    graph = Graph([], [Info(NAME, b"new")], delay=50)
    assert wait_until_up(World(graph), graph, NAME, set(), lambda: False, 10.0) == {}
    assert graph.looks == 1


def test_time_spent_waiting_for_a_cpu_does_not_count_toward_the_start_up(monkeypatch):
    """A busy machine keeps the program waiting for a CPU 0.9 s of every second: its node
    shows after 30 s of wall time, 3 s of its own, within a 10 s start-up."""
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
