"""This project's world: ``Simulation.step`` (physics, lidar, faults, recording; no ROS)."""

from __future__ import annotations

import time
from typing import Any

import numpy as np

from peers.scenario import COMMAND_EVERY, Run, Scenario, target, timed
from sim.engine import Simulation
from sim.lidar import Lidar
from sim.physics import World

NAME = "this world (pymunk + NumPy)"
PACKAGE = None


class _TimedLidar:
    """The lidar, with the time of each scan kept (a few hundred nanoseconds a scan)."""

    def __init__(self, lidar: Lidar, seconds: list[float]) -> None:
        self._lidar, self._seconds = lidar, seconds

    def scan(self, world: World) -> np.ndarray:
        start = time.perf_counter()
        ranges = self._lidar.scan(world)
        self._seconds.append(time.perf_counter() - start)
        return ranges

    def __getattr__(self, name: str) -> Any:
        return getattr(self._lidar, name)


def run(scenario: Scenario) -> Run:
    result = Run()
    sim = Simulation(World(scenario.spec))
    sim.lidar = _TimedLidar(sim.lidar, result.scan_seconds)  # type: ignore[assignment]
    world, step = sim.world, sim.step
    with timed(result):
        for i in range(scenario.steps):
            if i % COMMAND_EVERY == 0:
                world.set_command(*target(i))
            out = step()
            if out.scan is not None:
                result.record(world.pose, out.scan.ranges)
    return result
