"""Recording of a run: the trajectory at every odometry sample and every collision.

Kept apart from physics and ROS so a report can be built from plain data.
"""

from __future__ import annotations

import itertools
import math
import threading
from dataclasses import dataclass, field
from typing import Any

from sim.physics import Contact


@dataclass(frozen=True)
class Sample:
    """One odometry sample: sim time, pose and body-frame velocities."""

    t: float
    x: float
    y: float
    theta: float
    v: float
    w: float


@dataclass
class Recording:
    """Everything recorded in one run; thread safe to append to and read."""

    world: str = ""
    samples: list[Sample] = field(default_factory=list)
    collisions: list[Contact] = field(default_factory=list)
    _lock: threading.Lock = field(default_factory=threading.Lock, repr=False, compare=False)

    def add_sample(self, sample: Sample) -> None:
        with self._lock:
            self.samples.append(sample)

    def add_collision(self, contact: Contact) -> None:
        with self._lock:
            self.collisions.append(contact)

    def clear(self) -> None:
        with self._lock:
            self.samples.clear()
            self.collisions.clear()

    def snapshot(self) -> tuple[list[Sample], list[Contact]]:
        """Copies of the samples and collisions so far."""
        with self._lock:
            return list(self.samples), list(self.collisions)

    def distance(self) -> float:
        """Path length travelled (m)."""
        samples, _ = self.snapshot()
        return sum(math.dist((a.x, a.y), (b.x, b.y))
                   for a, b in itertools.pairwise(samples))

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready form: {world, trajectory: [[t, x, y, theta, v, w], ...], collisions}."""
        samples, collisions = self.snapshot()
        return {
            "world": self.world,
            "fields": ["t", "x", "y", "theta", "v", "w"],
            "trajectory": [[s.t, s.x, s.y, s.theta, s.v, s.w] for s in samples],
            "collisions": [{"t": c.t, "x": c.x, "y": c.y, "what": c.what} for c in collisions],
        }

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> Recording:
        """The inverse of :meth:`to_dict`."""
        return cls(world=data.get("world", ""),
                   samples=[Sample(*row) for row in data.get("trajectory", [])],
                   collisions=[Contact(**c) for c in data.get("collisions", [])])
