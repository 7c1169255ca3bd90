"""Fakes of the ROS graph and the world for the start-up check's tests
(:mod:`autograder.plugin.graph`, :mod:`autograder.plugin.student`): a graph whose
publishers appear after a number of looks, a world whose waits look at it, a wall clock
that moves with the looks."""

from __future__ import annotations

import contextlib
import dataclasses
from collections.abc import Callable, Iterator

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


class Clock:
    """Wall time that moves one second per look at the graph."""

    def __init__(self, graph: Graph) -> None:
        self.graph, self.start = graph, 1000.0

    def __call__(self) -> float:
        return self.start + self.graph.looks
