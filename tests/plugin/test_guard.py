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


# -- the wire: strangers on the domain, the student on another's ------------------------
GRADER, STUDENT, OTHER = 0, 200012, 200013


def _wired(graph: _Graph, sockets: list[tuple[int, int]], student: int = STUDENT,
           ) -> GraphWatch:
    from autograder.plugin.guard import Wire

    wire = Wire(domain=12, grader=frozenset({GRADER}), student=student,
                read=lambda: list(sockets))
    return GraphWatch(_Probe(graph), clock=_Clock(), wire=wire)


def test_the_grader_and_the_student_on_the_domain_are_nobody_to_charge(graph):
    watch = _wired(graph, [(12, GRADER), (12, STUDENT), (13, GRADER), (30, OTHER)])
    assert watch.charge_split() == ([], [])


def test_another_users_socket_on_the_domain_is_a_disturbance_not_the_students(graph):
    """A classmate's program joined this grading's domain: the student is not blamed."""
    sockets = [(12, GRADER), (12, OTHER)]
    watch = _wired(graph, sockets)
    assert watch.charge_split() == (
        [], [("a program of another user (uid 200013) joined this grading's ROS domain 12",
              200013)])
    sockets.remove((12, OTHER))
    assert watch.charge_split() == ([], [])  # gone: the next test is not disturbed


def test_the_students_socket_on_another_domain_is_tampering(graph):
    """The student's program joined another grading's domain: its own test fails."""
    watch = _wired(graph, [(12, STUDENT), (40, STUDENT)])
    assert watch.charge_split() == (["your program joined ROS domain 40, which is not its "
                                     "own"], [])


def test_the_grading_s_other_modules_are_the_same_student_not_strangers(graph):
    """A grading runs its modules in children on domains of their own, each with its
    user: the student's program of another module on this domain is no stranger (its own
    module's watch fails it for joining a domain not its own)."""
    from autograder.plugin.guard import Wire

    wire = Wire(domain=12, grader=frozenset({GRADER}), student=STUDENT,
                read=lambda: [(12, OTHER)], students=frozenset({STUDENT, OTHER}))
    assert wire.look() == []


def test_in_basic_isolation_only_other_users_are_strangers(graph):
    """The student runs as the grader's user there: its sockets cannot be told from the
    grader's anywhere; another user's on the domain are a stranger's."""
    watch = _wired(graph, [(12, GRADER), (40, GRADER), (12, 1001)], student=GRADER)
    assert watch.charge_split() == (
        [], [("a program of another user (uid 1001) joined this grading's ROS domain 12",
              1001)])


def test_ports_the_kernel_hands_out_belong_to_no_domain():
    """Fast DDS's own sending sockets take ports from the kernel's ephemeral range, which
    overlaps the blocks of domains above 100: those are nobody's domain, never a join."""
    from autograder.sandbox.domains import (
        DOMAIN_GAIN,
        PORT_BASE,
        domain_of_port,
        ephemeral_low,
    )

    assert domain_of_port(PORT_BASE + DOMAIN_GAIN * 12 + 11) == 12
    assert domain_of_port(ephemeral_low()) is None
    assert domain_of_port(ephemeral_low() + 1234) is None
    assert domain_of_port(PORT_BASE - 1) is None
