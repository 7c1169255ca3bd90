"""The tampering guard's watch, on a fake probe: what it finds on the graph and which test
each finding is charged to."""

from __future__ import annotations

import threading
from dataclasses import dataclass, field

import pytest

from autograder.plugin.guard import GraphWatch, tampering


@dataclass
class _Info:
    node_name: str


@dataclass
class _Graph:
    """A graph to edit: publishers per topic and node names; counts the looks at it."""

    publishers: dict[str, list[str]] = field(default_factory=dict)
    nodes: list[str] = field(default_factory=lambda: ["sim_world", "autograder_probe"])
    looks: int = 0
    looked: threading.Condition = field(default_factory=threading.Condition)

    reads: int = 0  # of the publisher lists

    def count_publishers(self, topic: str) -> int:
        return len(self.publishers.get(topic, []))

    def get_publishers_info_by_topic(self, topic: str) -> list[_Info]:
        self.reads += 1
        return [_Info(name) for name in self.publishers.get(topic, [])]

    def get_node_names_and_namespaces(self) -> list[tuple[str, str]]:
        with self.looked:
            self.looks += 1
            self.looked.notify_all()
        return [(name, "/") for name in self.nodes]

    def wait_looks(self, more: int, timeout: float = 5.0) -> bool:
        with self.looked:
            goal = self.looks + more
            return self.looked.wait_for(lambda: self.looks >= goal, timeout)


@dataclass
class _Probe:
    node: _Graph


class _Clock:
    def __init__(self) -> None:
        self.t = 0.0

    def __call__(self) -> float:
        self.t += 0.001  # every reading later than the last, as a monotonic clock's
        return self.t


@pytest.fixture
def graph() -> _Graph:
    return _Graph(publishers={"/clock": ["sim_world"], "/odom": ["sim_world"],
                              "/scan": ["sim_world"]})


@pytest.fixture
def watch(graph: _Graph) -> GraphWatch:
    return GraphWatch(_Probe(graph), clock=_Clock())


CLOCK = "node 'shouter' publishes on /clock, which the simulator owns"


def test_the_world_and_the_probe_are_no_tampering(graph):
    assert tampering(_Probe(graph)) == []


def test_foreign_publishers_and_a_second_grader_name_are_named(graph):
    graph.publishers["/clock"].append("shouter")
    graph.publishers["/scan"].append("liar")
    graph.nodes.append("autograder_probe")
    assert tampering(_Probe(graph)) == [
        CLOCK, "node 'liar' publishes on /scan, which the simulator owns",
        "a second node is named 'autograder_probe', the grader's name"]


def test_a_publisher_gone_before_the_test_ends_fails_that_test_only(graph, watch):
    watch.look()
    graph.publishers["/clock"].append("shouter")
    watch.look()
    graph.publishers["/clock"].remove("shouter")
    watch.look()
    assert watch.charge() == [CLOCK]
    assert watch.charge() == []  # the next test


def test_a_publisher_that_stays_fails_every_test_it_lives_through(graph, watch):
    graph.publishers["/odom"].append("shouter")
    assert [len(watch.charge()) for _ in range(3)] == [1, 1, 1]
    graph.publishers["/odom"].remove("shouter")
    watch.charge()  # the test during which it went
    assert watch.charge() == []


def test_a_publisher_seen_between_two_tests_fails_the_next(graph, watch):
    assert watch.charge() == []  # a test ends
    graph.publishers["/clock"].append("shouter")
    watch.look()  # between the tests
    graph.publishers["/clock"].remove("shouter")
    assert watch.charge() == [CLOCK]


def test_the_lists_are_read_again_only_when_the_counts_change(graph, watch):
    """While all is clean and no publisher came or went, a look only counts them."""
    watch.look()
    reads = graph.reads
    watch.look()
    assert graph.reads == reads
    graph.publishers["/scan"].append("shouter")
    watch.look()
    assert graph.reads > reads
    graph.publishers["/scan"] = ["sim_world", "liar"]  # the same count, another node
    assert watch.charge() == [
        "node 'shouter' publishes on /scan, which the simulator owns",
        "node 'liar' publishes on /scan, which the simulator owns"]


def test_each_finding_is_kept_with_when_it_was_seen(graph, watch):
    graph.publishers["/clock"].append("shouter")
    watch.look()
    watch.look()
    graph.publishers["/clock"].remove("shouter")
    watch.look()
    graph.publishers["/clock"].append("shouter")
    watch.look()
    spans = watch.seen[("publishes", "shouter", "/clock")]
    assert len(spans) == 2 and spans[0][0] < spans[0][1] < spans[1][0] == spans[1][1]


def test_the_watch_looks_on_its_own(graph):
    """A publisher that lives a few looks, between two charges, is caught by the thread."""
    watch = GraphWatch(_Probe(graph), every=0.005)
    watch.start()
    try:
        assert graph.wait_looks(1)
        graph.publishers["/clock"].append("shouter")
        assert graph.wait_looks(3)
        graph.publishers["/clock"].remove("shouter")
        assert graph.wait_looks(1)
    finally:
        watch.stop()
    assert watch.charge() == [CLOCK]
