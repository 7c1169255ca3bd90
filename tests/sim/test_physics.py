"""Physics of the world: determinism, limits, collisions, reset and run-time obstacles."""

from __future__ import annotations

import math

import pytest

from sim.physics import World
from sim.worldfile import Box, Circle, load_world


def _drive(world: World, commands: list[tuple[int, float, float]], steps: int) -> list:
    """Apply (step, linear, angular) commands at their steps; the pose after every step."""
    pending = dict((s, (v, w)) for s, v, w in commands)
    trajectory = []
    for i in range(steps):
        if i in pending:
            world.set_command(*pending[i])
        world.step()
        trajectory.append((world.time, *world.pose, *world.velocity))
    return trajectory


COMMANDS = [(0, 0.8, 0.5), (300, -0.3, -2.0), (700, 1.0, 0.0), (1200, 0.2, 2.5)]


def test_same_spec_and_commands_give_identical_trajectories() -> None:
    spec = load_world("obstacles")
    first = _drive(World(spec, seed=1), COMMANDS, 2000)
    second = _drive(World(spec, seed=1), COMMANDS, 2000)
    assert first == second  # bit for bit, not approximately


def test_reset_replays_identically() -> None:
    world = World(load_world("obstacles"))
    first = _drive(world, COMMANDS, 1500)
    world.reset()
    assert world.time == 0.0 and world.pose == (3.0, 3.0, 0.0)
    assert _drive(world, COMMANDS, 1500) == first


def test_time_is_whole_steps() -> None:
    world = World(load_world("empty_room"), dt=0.005)
    for _ in range(1000):
        world.step()
    assert world.steps == 1000 and world.time == 5.0


def test_speed_limits_are_enforced() -> None:
    world = World(load_world("empty_room"))
    world.set_command(5.0, -10.0)
    _drive(world, [], 400)
    v, w = world.velocity
    assert v == pytest.approx(1.0, abs=1e-3) and v <= 1.0 + 1e-9
    assert w == pytest.approx(-2.84, abs=1e-6)
    assert world.command == (1.0, -2.84)


def test_acceleration_limits_are_enforced() -> None:
    world = World(load_world("empty_room"))
    world.set_command(1.0, 2.0)
    steps = _drive(world, [], 400)
    for (t0, *_, v0, w0), (t1, *_, v1, w1) in zip(steps, steps[1:], strict=False):
        assert (v1 - v0) / (t1 - t0) <= 2.5 + 1e-6
        assert (w1 - w0) / (t1 - t0) <= 6.0 + 1e-6
    assert world.command == (1.0, 2.0)


def test_nan_command_is_ignored_as_zero() -> None:
    world = World(load_world("empty_room"))
    world.set_command(math.nan, math.nan)
    _drive(world, [], 10)
    assert world.pose == (3.0, 3.0, 0.0)


def test_driving_into_wall_stops_and_records_a_collision() -> None:
    world = World(load_world("wall_ahead"))
    world.set_command(0.5, 0.0)
    _drive(world, [], 800)
    contacts = world.drain_contacts()
    assert len(contacts) == 1
    assert contacts[0].what.startswith("wall")
    assert contacts[0].t == pytest.approx(1.0 / 0.5 * 0.895 + 0.1, abs=0.05)
    x, y, _ = world.pose
    assert x == pytest.approx(4.0 - 0.105, abs=0.005)  # stopped at the wall's face
    assert world.velocity[0] == pytest.approx(0.0, abs=1e-3)
    assert world.drain_contacts() == []


def test_obstacle_added_at_run_time_blocks_the_robot() -> None:
    world = World(load_world("empty_room"))
    world.add_obstacle(Circle(center=(4.0, 3.0), radius=0.2))
    world.add_obstacle(Box(center=(3.0, 4.0), size=(1.0, 0.2)))
    assert len(world.geometry[1]) == 1
    world.set_command(0.5, 0.0)
    _drive(world, [], 800)
    assert world.pose[0] == pytest.approx(4.0 - 0.2 - 0.105, abs=0.005)
    assert world.drain_contacts()[0].what.startswith("added circle")
    world.reset()
    assert len(world.geometry[1]) == 0  # run-time obstacles do not survive a reset


def test_the_direct_chipmunk_step_equals_pymunks_space_step() -> None:
    """The world steps Chipmunk without Space.step's Python when nothing is pending; the
    public path (taken when pymunk's internals differ) gives the same trajectory."""
    fast = World(load_world("obstacles"))
    public = World(load_world("obstacles"), direct_step=False)
    assert fast.steps_directly and not public.steps_directly
    for world in (fast, public):
        for i in range(1500):
            if i % 300 == 0:
                world.set_command(0.8 - i / 1000, 2 * math.sin(i / 200))
            if i == 500:
                world.add_obstacle(Circle(center=(3.0, 3.0), radius=0.2))
            world.step()
    assert fast.pose == public.pose
    assert fast.velocity == public.velocity
    assert fast.drain_contacts() == public.drain_contacts()
