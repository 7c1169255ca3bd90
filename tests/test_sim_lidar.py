"""Lidar ranges against known geometry, and its cost."""

from __future__ import annotations

import math
import time

import numpy as np
import pytest

from sim.lidar import Lidar
from sim.physics import World
from sim.worldfile import Circle, load_world


def test_wall_ahead_distances() -> None:
    world = World(load_world("wall_ahead"))
    ranges = Lidar().scan(world)
    assert len(ranges) == 360
    assert ranges[0] == pytest.approx(1.0, abs=1e-9)  # the wall's face is 1.0 m ahead
    assert ranges[10] == pytest.approx(1.0 / math.cos(math.radians(10)), abs=1e-9)
    assert ranges[90] == pytest.approx(3.0 - 0.025, abs=1e-9)  # outer wall, half thickness
    assert ranges[180] == pytest.approx(2.975, abs=1e-9)


def test_beyond_range_max_is_inf_and_too_close_is_minus_inf() -> None:
    world = World(load_world("empty_room"))
    lidar = Lidar(range_max=2.0)
    assert np.isposinf(lidar.scan(world)).all()  # every wall is 2.975 m away
    world.add_obstacle(Circle(center=(3.2, 3.0), radius=0.09))
    assert Lidar().scan(world)[0] == -np.inf  # 0.11 m < range_min


def test_circle_distance_and_rotation() -> None:
    world = World(load_world("empty_room"))
    world.add_obstacle(Circle(center=(3.0, 4.0), radius=0.5))
    ranges = Lidar().scan(world)
    assert ranges[90] == pytest.approx(0.5, abs=1e-9)  # left of a robot facing +x
    x, y, theta = world.pose
    segments, circles = world.geometry
    turned = Lidar().cast(x, y, math.pi / 2, segments, circles)
    assert turned[0] == pytest.approx(0.5, abs=1e-9)


def test_scan_is_well_under_a_millisecond() -> None:
    world = World(load_world("obstacles"))
    lidar = Lidar()
    lidar.scan(world)
    start = time.perf_counter()
    for _ in range(200):
        lidar.scan(world)
    assert (time.perf_counter() - start) / 200 < 1e-3
