"""Lidar ranges against known geometry, its mount, its seeded noise, REP 117, and its cost."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from sim.engine import Simulation
from sim.lidar import Lidar
from sim.physics import World
from sim.worldfile import Circle, LidarSpec, Pose, load_world

IDEAL = Lidar(noise_sigma=0.0, mount=(0.0, 0.0, 0.0))
"""A noise-free scanner at the robot's centre: the geometry alone."""


def _world(name: str = "empty_room", **changes: object) -> World:
    return World(dataclasses.replace(load_world(name), **changes))


def test_wall_ahead_distances() -> None:
    world = World(load_world("wall_ahead"))
    ranges = IDEAL.scan(world)
    assert len(ranges) == 360
    assert ranges[0] == pytest.approx(1.0, abs=1e-9)  # the wall's face is 1.0 m ahead
    assert ranges[10] == pytest.approx(1.0 / math.cos(math.radians(10)), abs=1e-9)
    assert ranges[90] == pytest.approx(3.0 - 0.025, abs=1e-9)  # outer wall, half thickness
    assert ranges[180] == pytest.approx(2.975, abs=1e-9)


def test_beyond_range_max_is_inf_and_too_close_is_minus_inf() -> None:
    world = World(load_world("empty_room"))
    assert np.isposinf(Lidar(range_max=2.0).scan(world)).all()  # every wall is 2.975 m away
    world.add_obstacle(Circle(center=(3.2, 3.0), radius=0.09))
    assert IDEAL.scan(world)[0] == -np.inf  # 0.11 m < range_min


def test_circle_distance_and_rotation() -> None:
    world = World(load_world("empty_room"))
    world.add_obstacle(Circle(center=(3.0, 4.0), radius=0.5))
    ranges = IDEAL.scan(world)
    assert ranges[90] == pytest.approx(0.5, abs=1e-9)  # left of a robot facing +x
    x, y, theta = world.pose
    segments, circles = world.geometry
    turned = IDEAL.cast(x, y, math.pi / 2, segments, circles)
    assert turned[0] == pytest.approx(0.5, abs=1e-9)


def test_defaults_are_a_turtlebot3_burger_lds() -> None:
    lidar = Lidar()
    assert lidar.noise_sigma == 0.01  # TurtleBot3's Gazebo LDS model
    assert lidar.mount == (-0.032, 0.0, 0.0)  # base_scan in base_footprint
    assert (lidar.beams, lidar.range_min, lidar.range_max) == (360, 0.12, 3.5)
    assert Lidar.from_spec(LidarSpec()) == lidar
    spec = LidarSpec(beams=180, range_min=0.2, range_max=8.0, noise_sigma=0.02,
                     mount=(0.1, 0.05, 0.3))
    assert Lidar.from_spec(spec) == Lidar(beams=180, range_min=0.2, range_max=8.0,
                                          noise_sigma=0.02, mount=(0.1, 0.05, 0.3))
    assert Simulation(World(load_world("empty_room"))).lidar == lidar


def test_the_scan_is_cast_from_the_mount() -> None:
    world = World(load_world("wall_ahead"))
    behind = Lidar(noise_sigma=0.0).scan(world)  # 3.2 cm behind the centre
    assert behind[0] == pytest.approx(1.032, abs=1e-9)
    assert behind[180] == pytest.approx(2.975 - 0.032, abs=1e-9)
    assert behind[90] == pytest.approx(2.975, abs=1e-9)  # sideways: as far as before
    left = Lidar(noise_sigma=0.0, mount=(0.0, 0.5, 0.0)).scan(world)
    assert left[90] == pytest.approx(2.475, abs=1e-9)
    turned = Lidar(noise_sigma=0.0, mount=(0.0, 0.0, math.pi / 2)).scan(world)
    assert turned[0] == pytest.approx(2.975, abs=1e-9)  # beam 0 now looks left (+y)
    assert turned[270] == pytest.approx(1.0, abs=1e-9)  # and the wall is to its right


def test_the_mount_turns_with_the_robot() -> None:
    world = _world(start=Pose(3.0, 3.0, math.pi / 2))  # facing +y
    ranges = Lidar(noise_sigma=0.0).scan(world)
    assert ranges[0] == pytest.approx(2.975 + 0.032, abs=1e-9)  # scanner at y = 2.968
    assert ranges[180] == pytest.approx(2.975 - 0.032, abs=1e-9)


def _residuals(world: World, lidar: Lidar, scans: int) -> np.ndarray:
    """Noisy minus exact readings in range over ``scans`` scans, 0.1 s of sim time apart."""
    exact = dataclasses.replace(lidar, noise_sigma=0.0)
    out = []
    for _ in range(scans):
        for _step in range(20):
            world.step()
        noisy, truth = lidar.scan(world), exact.scan(world)
        both = np.isfinite(noisy) & np.isfinite(truth)
        out.append(noisy[both] - truth[both])
    return np.concatenate(out)


def test_noise_is_gaussian_around_the_geometry() -> None:
    world = World(load_world("obstacles"))
    residuals = _residuals(world, Lidar(), 10)
    n = len(residuals)
    assert n > 2500
    # Five standard errors: a seeded draw, so this holds or fails the same way every run.
    assert abs(residuals.mean()) < 5 * 0.01 / math.sqrt(n)
    assert residuals.std() == pytest.approx(0.01, rel=5 / math.sqrt(2 * n))
    assert abs(residuals).max() < 6 * 0.01
    assert 0.6 < float((abs(residuals) < 0.01).mean()) < 0.76  # 68% within one sigma


def test_noise_sigma_comes_from_the_world_file(tmp_path) -> None:
    path = tmp_path / "noisy.yaml"
    path.write_text("lidar: {noise_sigma: 0.05, mount: [0, 0, 0]}\n")
    world = World(load_world(path))
    sim = Simulation(world)
    assert (sim.lidar.noise_sigma, sim.lidar.mount) == (0.05, (0.0, 0.0, 0.0))
    residuals = _residuals(world, sim.lidar, 10)
    assert residuals.std() == pytest.approx(0.05, rel=0.1)
    path.write_text("lidar: {noise_sigma: 0}\n")
    world = World(load_world(path))
    assert np.array_equal(Simulation(world).lidar.scan(world), Lidar(noise_sigma=0).scan(world))


def _drive(seed: int, steps: int = 400) -> list[np.ndarray]:
    sim = Simulation(World(load_world("obstacles"), seed=seed))
    sim.world.set_command(0.3, 0.4)
    return [out.scan.ranges for out in (sim.step() for _ in range(steps)) if out.scan]


def test_same_seed_same_commands_same_ranges_bit_for_bit() -> None:
    first, again, other = _drive(3), _drive(3), _drive(4)
    assert len(first) == 20
    assert all(np.array_equal(a, b) for a, b in zip(first, again, strict=True))
    assert not any(np.array_equal(a, b) for a, b in zip(first, other, strict=True))


def test_reset_restarts_the_noise() -> None:
    sim = Simulation(World(load_world("obstacles"), seed=5))
    before = [out.scan.ranges for out in (sim.step() for _ in range(100)) if out.scan]
    sim.lidar.scan(sim.world)  # asking for a scan in between draws nothing from the stream
    sim.reset()
    after = [out.scan.ranges for out in (sim.step() for _ in range(100)) if out.scan]
    assert all(np.array_equal(a, b) for a, b in zip(before, after, strict=True))


def test_rep117_holds_with_noise() -> None:
    world = World(load_world("empty_room"))
    # The walls 2.975 m off straight ahead and behind, right at range_max: noise pushes
    # some readings past it (+inf, never a finite reading above range_max).
    edge = Lidar(range_max=2.975, mount=(0.0, 0.0, 0.0))
    ranges = np.concatenate([edge.noisy(edge.cast(*world.pose, *world.geometry), 0, t)
                             for t in np.arange(0.0, 2.0, 0.1)])
    finite = ranges[np.isfinite(ranges)]
    assert np.isposinf(ranges).any() and len(finite) > 0
    assert finite.max() <= 2.975 and not np.isneginf(ranges).any()
    # A pillar 0.1201 m away, just past range_min (not on it: the exact cast may round
    # either way there): -inf or at least range_min, never less.
    world.add_obstacle(Circle(center=(3.2201, 3.0), radius=0.1))
    near = Lidar(mount=(0.0, 0.0, 0.0))
    first = np.array([near.noisy(near.cast(*world.pose, *world.geometry), 0, t)[0]
                      for t in np.arange(0.0, 2.0, 0.1)])
    assert np.isneginf(first).any() and np.isfinite(first).any()
    assert (first[np.isfinite(first)] >= near.range_min).all()
    # Nothing in range stays +inf: no noise is drawn for it.
    assert np.isposinf(Lidar(range_max=2.0).scan(World(load_world("empty_room")))).all()
