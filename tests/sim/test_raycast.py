"""The fast ray cast gives the ranges of the plain beams x shapes computation it replaced."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sim import raycast
from sim.lidar import Lidar
from sim.physics import World
from sim.worldfile import WORLDS_DIR, Box, Circle, load_world

# The scanner at the robot's centre and without noise: these tests are about geometry.
EXACT = Lidar(noise_sigma=0.0, mount=(0.0, 0.0, 0.0))

def reference_cast(lidar: Lidar, x: float, y: float, theta: float, segments: np.ndarray,
                   circles: np.ndarray) -> np.ndarray:
    """``Lidar.cast`` as it was: every beam against every shape, t = C / (d x E)."""
    a = theta + lidar.angles()
    dx, dy = np.cos(a)[:, None], np.sin(a)[:, None]
    best = np.full((lidar.beams, 1), np.inf)
    if len(segments):
        px, py = segments[:, 0] - x, segments[:, 1] - y
        ex, ey = segments[:, 2] - segments[:, 0], segments[:, 3] - segments[:, 1]
        denom = dx * ey - dy * ex
        with np.errstate(divide="ignore", invalid="ignore"):
            t = (px * ey - py * ex) / denom
            s = (px * dy - py * dx) / denom
        hit = (denom != 0) & (t >= 0) & (s >= 0) & (s <= 1)
        best = np.minimum(best, np.where(hit, t, np.inf).min(axis=1, keepdims=True))
    if len(circles):
        fx, fy = x - circles[:, 0], y - circles[:, 1]
        b = dx * fx + dy * fy
        c = fx * fx + fy * fy - circles[:, 2] ** 2
        disc = b * b - c
        root = np.sqrt(np.maximum(disc, 0.0))
        near, far = -b - root, -b + root
        t = np.where(near >= 0, near, far)
        t = np.where((disc >= 0) & (t >= 0), t, np.inf)
        best = np.minimum(best, t.min(axis=1, keepdims=True))
    ranges = best[:, 0]
    ranges[ranges > lidar.range_max] = np.inf
    ranges[ranges < lidar.range_min] = -np.inf
    return ranges


def assert_same_ranges(fast: np.ndarray, slow: np.ndarray) -> None:
    """Equal up to rounding: the same beams out of range, the rest within 1e-9 m."""
    assert fast.dtype == np.float64 and fast.shape == slow.shape
    finite = np.isfinite(slow)
    np.testing.assert_array_equal(fast[~finite], slow[~finite])
    np.testing.assert_allclose(fast[finite], slow[finite], rtol=0, atol=1e-9)


def _crowded() -> World:
    """The standard world with obstacles added, one of them over the start pose."""
    world = World(load_world("obstacles"))
    world.add_obstacle(Box(center=(2.0, 3.5), size=(0.3, 0.6), angle=1.1))
    world.add_obstacle(Circle(center=(3.6, 2.2), radius=0.4))
    world.add_obstacle(Circle(center=(3.05, 3.0), radius=0.2))
    return world


WORLDS = {path.stem: (lambda name=path.stem: World(load_world(name)))
          for path in sorted(WORLDS_DIR.glob("*.yaml"))}
WORLDS["crowded"] = _crowded


@pytest.mark.parametrize("make", WORLDS.values(), ids=WORLDS.keys())
def test_random_poses_match_the_reference(make) -> None:
    world = make()
    segments, circles = world.geometry
    width, height = world.spec.size
    rng = np.random.default_rng(7)
    lidar = Lidar()
    # Beyond the arena too: poses inside walls, boxes and pillars see the far side.
    for x, y, theta in zip(rng.uniform(-0.3, width + 0.3, 300),
                           rng.uniform(-0.3, height + 0.3, 300),
                           rng.uniform(-2 * math.pi, 2 * math.pi, 300), strict=True):
        assert_same_ranges(lidar.cast(x, y, theta, segments, circles),
                           reference_cast(lidar, x, y, theta, segments, circles))


LIDARS = {"90 beams": Lidar(beams=90), "offset start": Lidar(angle_min=-math.pi),
          "no minimum": Lidar(range_min=0.0), "long range": Lidar(range_max=20.0),
          "short range": Lidar(range_min=0.5, range_max=1.0), "7 beams": Lidar(beams=7)}


@pytest.mark.parametrize("lidar", LIDARS.values(), ids=LIDARS.keys())
def test_other_lidars_match_the_reference(lidar: Lidar) -> None:
    world = _crowded()
    segments, circles = world.geometry
    rng = np.random.default_rng(11)
    for x, y, theta in rng.uniform(0.0, 6.0, (100, 3)):
        assert_same_ranges(lidar.cast(x, y, theta, segments, circles),
                           reference_cast(lidar, x, y, theta, segments, circles))


def _loop(*corners: tuple[float, float]) -> np.ndarray:
    """The closed chain of edges through ``corners``, as World lists a box's."""
    return np.array([(*a, *b) for a, b in zip(corners, corners[1:] + corners[:1],
                                              strict=True)], dtype=float)


# No corner lies exactly on a beam: there the reference's rounding may miss both edges.
SQUARE = ((0.5, -0.4), (1.5, -0.4), (1.5, 0.6), (0.5, 0.6))
L_SHAPE = ((0.5, -1.0), (2.0, -1.0), (2.0, 0.2), (1.0, 0.2), (1.0, 1.1), (0.5, 1.1))
NO_CIRCLES = np.zeros((0, 3))
SHAPES = {
    "nothing": (np.zeros((0, 4)), NO_CIRCLES),
    "one segment": (np.array([[1.0, -0.8, 1.0, 1.2]]), NO_CIRCLES),
    "one circle": (np.zeros((0, 4)), np.array([[0.0, 2.0, 0.5]])),
    "inside a circle": (np.zeros((0, 4)), np.array([[0.1, 0.0, 1.0]])),
    "square": (_loop(*SQUARE), NO_CIRCLES),
    "square clockwise": (_loop(*SQUARE[::-1]), NO_CIRCLES),
    "inside a square": (_loop((-0.5, -0.4), (0.6, -0.4), (0.6, 0.7), (-0.5, 0.7)), NO_CIRCLES),
    "L-shaped loop": (_loop(*L_SHAPE), NO_CIRCLES),
    "open chain": (_loop(*SQUARE)[:3], np.array([[-1.0, 0.0, 0.3]])),
}


@pytest.mark.parametrize("shapes", SHAPES.values(), ids=SHAPES.keys())
def test_few_shapes_match_the_reference(shapes: tuple[np.ndarray, np.ndarray]) -> None:
    lidar = Lidar()
    for theta in (0.0, 0.3, -2.0):
        assert_same_ranges(lidar.cast(0.0, 0.0, theta, *shapes),
                           reference_cast(lidar, 0.0, 0.0, theta, *shapes))


def test_only_closed_convex_loops_have_sides() -> None:
    """Edges facing away are left out only where that cannot change a range."""
    assert list(raycast.prepare(_loop(*SQUARE), NO_CIRCLES).sides) == [1.0] * 4
    assert list(raycast.prepare(_loop(*SQUARE[::-1]), NO_CIRCLES).sides) == [-1.0] * 4
    assert raycast.prepare(_loop(*L_SHAPE), NO_CIRCLES).sides is None
    assert raycast.prepare(_loop(*SQUARE)[:3], NO_CIRCLES).sides is None
    world = World(load_world("obstacles"))  # four thick walls and three boxes
    assert list(raycast.prepared(*world.geometry).groups) == [0, 4, 8, 12, 16, 20, 24]


@pytest.mark.parametrize("corners", [SQUARE, SQUARE[::-1]], ids=["ccw", "cw"])
def test_a_beam_through_a_corner_hits_it(corners) -> None:
    """Corners at exactly 45 degrees: the edge facing the beam is hit at its very end."""
    square = _loop(*((x, y - 0.1) for x, y in corners))  # (0.5, +-0.5) and beyond
    ranges = Lidar().cast(0.0, 0.0, 0.0, square, NO_CIRCLES)
    assert ranges[45] == pytest.approx(math.sqrt(0.5), abs=1e-9)
    assert ranges[315] == pytest.approx(math.sqrt(0.5), abs=1e-9)


def test_inside_a_box_the_robot_sees_its_walls() -> None:
    world = World(load_world("empty_room"))
    world.add_obstacle(Box(center=(3.2, 3.0), size=(1.0, 0.6)))
    ranges = EXACT.scan(world)
    assert ranges[0] == pytest.approx(0.7, abs=1e-9)
    assert ranges[90] == pytest.approx(0.3, abs=1e-9)
    assert ranges[180] == pytest.approx(0.3, abs=1e-9)


def test_world_geometry_is_prepared_once_per_change() -> None:
    world = World(load_world("obstacles"))
    segments, circles = world.geometry
    assert not segments.flags.writeable and not circles.flags.writeable
    first = raycast.prepared(segments, circles)
    assert raycast.prepared(*world.geometry) is first
    world.add_obstacle(Circle(center=(3.0, 4.0), radius=0.5))
    assert world.geometry[1] is not circles
    assert raycast.prepared(*world.geometry) is not first
    assert EXACT.scan(world)[90] == pytest.approx(0.5, abs=1e-9)  # the new pillar


def test_arrays_the_caller_may_change_are_read_afresh() -> None:
    segments = np.array([[1.0, -1.0, 1.0, 1.0]])
    circles = np.zeros((0, 3))
    lidar = Lidar()
    assert lidar.cast(0.0, 0.0, 0.0, segments, circles)[0] == pytest.approx(1.0)
    segments[:, [0, 2]] = 2.0
    assert lidar.cast(0.0, 0.0, 0.0, segments, circles)[0] == pytest.approx(2.0)


def test_many_worlds_do_not_pile_up_prepared_geometry() -> None:
    worlds = [World(load_world("empty_room")) for _ in range(40)]
    for world in worlds:
        world.add_obstacle(Circle(center=(3.0, 4.0), radius=0.5))
        assert EXACT.scan(world)[90] == pytest.approx(0.5, abs=1e-9)
    assert raycast.cached() <= raycast.CACHED_AT_MOST
