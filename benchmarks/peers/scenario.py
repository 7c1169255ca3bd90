"""The shared scenario every simulator runs, and the check of their scans.

The standard world (``obstacles``: a 6 x 6 m room, three boxes, three pillars), 60 s of
simulation at 200 Hz physics, the same open-loop commands (a new target every second,
reached within the robot's acceleration limits) and a 360-beam scan every 0.1 s.  Each
scan is checked afterwards against the analytic geometry from the pose the simulator
reported, outside the timed loop.
"""

from __future__ import annotations

import contextlib
import math
import time
from collections.abc import Iterator
from dataclasses import dataclass, field, replace

import numpy as np

from sim.physics import box_corners
from sim.worldfile import Box, WorldSpec, load_world

WORLD = "obstacles"
DT = 0.005
SIM_SECONDS = 60.0
SCAN_EVERY = 20
"""Physics steps between scans (10 Hz)."""
COMMAND_EVERY = 200
"""Physics steps between new targets (1 Hz)."""
BEAMS = 360
RANGE_MIN, RANGE_MAX = 0.12, 3.5
HEIGHT = 0.5
"""Height of walls, boxes and pillars in the 3D peers (m); beams run at mid-height of
the robot."""
ROBOT_HEIGHT = 0.2


def target(step: int) -> tuple[float, float]:
    """The commanded (linear, angular) velocity from this step on: wander in arcs."""
    i = step - step % COMMAND_EVERY
    return 0.4, math.sin(i / COMMAND_EVERY)


@dataclass(frozen=True)
class Block:
    """A rectangle: centre, half extents and yaw (walls and boxes alike)."""

    x: float
    y: float
    half_width: float
    half_height: float
    yaw: float

    @property
    def box(self) -> Box:
        return Box(center=(self.x, self.y), size=(2 * self.half_width, 2 * self.half_height),
                   angle=self.yaw)


@dataclass(frozen=True)
class Scenario:
    """What every simulator builds: blocks, pillars (x, y, r), the start and the limits."""

    spec: WorldSpec
    blocks: tuple[Block, ...]
    pillars: tuple[tuple[float, float, float], ...]
    steps: int = round(SIM_SECONDS / DT)

    @property
    def start(self) -> tuple[float, float, float]:
        return self.spec.start.x, self.spec.start.y, self.spec.start.theta

    def segments(self) -> np.ndarray:
        """Every block's four edges as (N, 4) [x1 y1 x2 y2]."""
        edges = []
        for block in self.blocks:
            corners = box_corners(block.box)
            edges += [(*a, *b) for a, b in zip(corners, corners[1:] + corners[:1],
                                               strict=True)]
        return np.array(edges, dtype=float).reshape(-1, 4)

    def circles(self) -> np.ndarray:
        return np.array(self.pillars, dtype=float).reshape(-1, 3)


def load() -> Scenario:
    """The shared scenario from the standard world file, its scanner as the peers' are: at
    the robot's centre and exact (the world's seeded noise and mount offset are ours alone;
    with them every scan would differ from the geometry the check holds it to)."""
    spec = load_world(WORLD)
    spec = replace(spec, lidar=replace(spec.lidar, noise_sigma=0.0, mount=(0.0, 0.0, 0.0)))
    blocks = []
    for (x1, y1), (x2, y2) in spec.all_walls():
        length = math.hypot(x2 - x1, y2 - y1)
        blocks.append(Block((x1 + x2) / 2, (y1 + y2) / 2, length / 2,
                            spec.wall_thickness / 2, math.atan2(y2 - y1, x2 - x1)))
    for box in spec.obstacles.boxes:
        blocks.append(Block(*box.center, box.size[0] / 2, box.size[1] / 2, box.angle))
    pillars = tuple((*c.center, c.radius) for c in spec.obstacles.circles)
    return Scenario(spec, tuple(blocks), pillars)


class Drive:
    """The open-loop commands within the robot's acceleration limits, step by step, as
    ``sim.physics.World`` applies them; peers that take velocities use this."""

    def __init__(self, scenario: Scenario) -> None:
        limits = scenario.spec.limits
        self._dv, self._dw = limits.max_linear_accel * DT, limits.max_angular_accel * DT
        self._target = self._now = (0.0, 0.0)

    def step(self, step: int) -> tuple[float, float]:
        """The (linear, angular) velocity to drive during ``step``."""
        if step % COMMAND_EVERY == 0:
            self._target = target(step)
        if self._now != self._target:
            (tv, tw), (v, w) = self._target, self._now
            self._now = (v + max(-self._dv, min(self._dv, tv - v)),
                         w + max(-self._dw, min(self._dw, tw - w)))
        return self._now


def beam_angles() -> np.ndarray:
    return np.arange(BEAMS) * (2 * math.pi / BEAMS)


def conventions(raw: np.ndarray) -> np.ndarray:
    """Distances (inf where nothing was hit) as the lidar reports them: +inf beyond
    ``RANGE_MAX``, -inf under ``RANGE_MIN``."""
    out = np.asarray(raw, dtype=float).copy()
    out[out > RANGE_MAX] = np.inf
    out[out < RANGE_MIN] = -np.inf
    return out


def exact_ranges(scenario: Scenario, x: float, y: float, theta: float,
                 angles: np.ndarray | None = None) -> np.ndarray:
    """The analytic ranges: every beam against every edge and pillar, in float64."""
    a = theta + (beam_angles() if angles is None else angles)
    dx, dy = np.cos(a)[:, None], np.sin(a)[:, None]
    seg, cir = scenario.segments(), scenario.circles()
    px, py = seg[:, 0] - x, seg[:, 1] - y
    ex, ey = seg[:, 2] - seg[:, 0], seg[:, 3] - seg[:, 1]
    denom = dx * ey - dy * ex
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (px * ey - py * ex) / denom
        s = (px * dy - py * dx) / denom
    best = np.where((denom != 0) & (t >= 0) & (s >= 0) & (s <= 1), t, np.inf).min(axis=1)
    fx, fy = x - cir[:, 0], y - cir[:, 1]
    b = dx * fx + dy * fy
    c = fx * fx + fy * fy - cir[:, 2] ** 2
    disc = b * b - c
    root = np.sqrt(np.maximum(disc, 0.0))
    near = np.where(-b - root >= 0, -b - root, -b + root)
    best = np.minimum(best, np.where((disc >= 0) & (near >= 0), near, np.inf).min(axis=1))
    return conventions(best)


@dataclass
class Run:
    """One timed run: wall and CPU seconds of the loop, what the scans cost, the scans."""

    wall: float = 0.0
    cpu: float = 0.0
    """CPU seconds of the whole process over the loop (all its threads)."""
    angles: np.ndarray | None = None
    """The beams' angles in the robot's frame, when not :func:`beam_angles`."""
    scan_seconds: list[float] = field(default_factory=list)
    poses: list[tuple[float, float, float]] = field(default_factory=list)
    scans: list[np.ndarray] = field(default_factory=list)

    def record(self, pose: tuple[float, float, float], ranges: np.ndarray) -> None:
        self.poses.append(pose)
        self.scans.append(ranges)


@contextlib.contextmanager
def timed(run: Run) -> Iterator[None]:
    """Time the block (the simulation loop) into ``run.wall`` and ``run.cpu``."""
    wall, cpu = time.perf_counter(), time.process_time()
    yield
    run.wall, run.cpu = time.perf_counter() - wall, time.process_time() - cpu


@dataclass(frozen=True)
class Check:
    """How a run's scans compare with the analytic ranges."""

    scans: int
    beams: int
    max_error: float
    """Largest |difference| (m) over beams both call in range."""
    off: int
    """Beams more than ``TOLERANCE`` off, or in range for one and not the other."""


TOLERANCE = 0.01


def check(scenario: Scenario, run: Run) -> Check:
    worst, off, beams = 0.0, 0, 0
    for (x, y, theta), ranges in zip(run.poses, run.scans, strict=True):
        exact = exact_ranges(scenario, x, y, theta, run.angles)
        got = conventions(ranges)
        beams += len(exact)
        finite = np.isfinite(exact) & np.isfinite(got)
        error = np.abs(got[finite] - exact[finite])
        off += int(np.count_nonzero(error > TOLERANCE))
        off += int(np.count_nonzero(~finite & (got != exact)))
        worst = max(worst, float(error.max(initial=0.0)))
    return Check(len(run.scans), beams, worst, off)
