"""How the grader waits for a student's node to start (graph and world stood in by fakes).

A restarted program's node has the name of the instance before it, which lingers on the
graph (a killed process stays listed until its DDS lease runs out, and the name can outlive
the instance's endpoints): only publishers the graph did not show before the start may
count as the new instance's, and a name alone never does. (The graph check itself, and
the time a start-up may take: tests/plugin/test_graph.py.)
"""

from __future__ import annotations

from types import SimpleNamespace

from graph_fakes import Graph, Info, World

from autograder.plugin.student import StudentNode, endpoints_of, wait_for_node_up

NAME = "obstacle_avoider"


def start(graph: Graph, world: World, stale: set[bytes]) -> StudentNode:
    probe = SimpleNamespace(node=graph, node_names=graph.names, world=world)
    process = SimpleNamespace(running=lambda: True, started_at=0.0, returncode=None, pid=0)
    node = StudentNode(process, NAME, probe)
    exercise = SimpleNamespace(node=NAME, startup_timeout=20.0, file="obstacle_avoider.py")
    wait_for_node_up(exercise, node, world, stale)
    return node


def test_a_restart_waits_for_the_new_instance_not_the_lingering_one():
    old, new = Info(NAME, b"old"), Info(NAME, b"new")
    graph = Graph([old], [new], delay=5)
    world = World(graph)
    stale = endpoints_of(SimpleNamespace(node=graph), NAME)
    assert stale == {b"old"}
    start(graph, world, stale)
    assert len(world.held_while_waiting) == 6  # not before the new instance showed
    assert all(world.held_while_waiting) and not world.holding


def test_a_lingering_name_without_endpoints_is_not_the_new_instance():
    # Seen in a stress run: the earlier instance's endpoints were gone, its name was not,
    # and a wait that took the name found the node 2 ms after the start.
    graph = Graph([], [Info(NAME, b"new")], delay=3, lingering={NAME})
    world = World(graph)
    stale = endpoints_of(SimpleNamespace(node=graph), NAME)
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
    assert endpoints_of(SimpleNamespace(node=graph), NAME) == {b"a"}
