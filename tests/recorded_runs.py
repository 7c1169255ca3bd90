"""Runs of the simulated world driven as a node would drive it, and the test results a
report holds them under: the report tests' data (tests/render/)."""

from __future__ import annotations

import json
import math
from fractions import Fraction

from autograder.core.results import TestResult
from sim.engine import Simulation
from sim.physics import World
from sim.recorder import Recording
from sim.worldfile import Fault, load_world


def driven(world: str, steps: int = 800) -> Simulation:
    """The world after ``steps`` physics steps at 0.5 m/s straight ahead."""
    sim = Simulation(World(load_world(world)))
    sim.world.set_command(0.5, 0.0)
    for _ in range(steps):
        sim.step()
    return sim


def recorded(world: str, seconds: float, linear: float = 0.4, turn: float = 0.8,
             faults: tuple[Fault, ...] = ()) -> Recording:
    """A run of the simulated world, driven as a node would (a command every 0.1 s), as
    the grader reads it back from its child's report (through JSON)."""
    sim = Simulation(World(load_world(world)))
    for fault in faults:
        sim.inject(fault)
    for i in range(round(seconds / sim.world.dt)):
        if i % 20 == 0:
            sim.set_command(linear, turn * math.sin(i / 300))
        sim.step()
    return Recording.from_dict(json.loads(json.dumps(sim.recording.to_dict())))


def a_test(module: str, name: str, label: str) -> TestResult:
    return TestResult(name, label, Fraction(1), Fraction(1), "passed",
                      nodeid=f"tests/public/{module}::{name}")
