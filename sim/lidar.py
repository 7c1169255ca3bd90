"""A 360-beam 2D lidar cast against the world's segments and circles with NumPy.

All beams are intersected with all segments and circles at once (:mod:`sim.raycast`,
with the geometry prepared once per change; its cost: ``benchmarks/bench_sim.py``).  The
scan is cast from
the scanner's mount point (``base_scan``, by default 3.2 cm behind the robot's centre as
on a TurtleBot3 Burger), and each reading in range gets Gaussian noise (sigma 0.01 m, as
TurtleBot3's Gazebo model) drawn from the world's seed and the scan's time: the same
seed and commands give the same ranges bit for bit, whatever else asks for scans.
Readings follow REP 117 after the noise: nothing within ``range_max`` gives ``+inf``; a
hit closer than ``range_min`` gives ``-inf``.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from sim import raycast
from sim.physics import World
from sim.worldfile import LIDAR_MOUNT, LIDAR_NOISE_SIGMA, LidarSpec

# Keeps the noise's random stream apart from the faults' (sim.faults draws with
# [seed, fault index, time]).
_NOISE_STREAM = 0x4C445331


@dataclass(frozen=True)
class Lidar:
    """An LDS-01-like scanner mounted on the robot (frame ``base_scan``)."""

    beams: int = 360
    range_min: float = 0.12
    range_max: float = 3.5
    angle_min: float = 0.0
    noise_sigma: float = LIDAR_NOISE_SIGMA
    mount: tuple[float, float, float] = LIDAR_MOUNT
    """(x, y, yaw) of ``base_scan`` in ``base_footprint`` (m, m, rad)."""

    @classmethod
    def from_spec(cls, spec: LidarSpec) -> Lidar:
        """The scanner a world file's ``lidar:`` section describes."""
        return cls(beams=spec.beams, range_min=spec.range_min, range_max=spec.range_max,
                   noise_sigma=spec.noise_sigma, mount=spec.mount)

    @property
    def angle_increment(self) -> float:
        return 2 * math.pi / self.beams

    @property
    def angle_max(self) -> float:
        return self.angle_min + (self.beams - 1) * self.angle_increment

    def angles(self) -> np.ndarray:
        """Beam angles in the sensor frame."""
        return self.angle_min + np.arange(self.beams) * self.angle_increment

    def origin(self, x: float, y: float, theta: float) -> tuple[float, float, float]:
        """The scanner's pose in the world for a robot (base_footprint) at (x, y, theta)."""
        mx, my, yaw = self.mount
        c, s = math.cos(theta), math.sin(theta)
        return x + c * mx - s * my, y + s * mx + c * my, theta + yaw

    def scan(self, world: World) -> np.ndarray:
        """Ranges (float64, one per beam) seen from the mount at the robot's current pose,
        with the world's noise for this instant."""
        segments, circles = world.geometry
        exact = self.cast(*self.origin(*world.pose), segments, circles)
        return self.noisy(exact, world.seed, world.time)

    def noisy(self, ranges: np.ndarray, seed: int, t: float) -> np.ndarray:
        """``ranges`` with Gaussian noise on the readings in range, from a stream fixed by
        (``seed``, ``t``); readings the noise pushes out of range follow REP 117."""
        if self.noise_sigma <= 0:
            return ranges
        rng = np.random.default_rng([seed, _NOISE_STREAM, round(t * 1e6)])
        noise = rng.normal(0.0, self.noise_sigma, len(ranges))
        out = np.where(np.isfinite(ranges), ranges + noise, ranges)
        return self._rep117(out)

    def cast(self, x: float, y: float, theta: float, segments: np.ndarray,
             circles: np.ndarray) -> np.ndarray:
        """Exact ranges from (x, y) with heading theta against the given geometry."""
        return raycast.cast(x, y, theta, raycast.prepared(segments, circles),
                            _directions(self), self.range_min, self.range_max)

    def _rep117(self, ranges: np.ndarray) -> np.ndarray:
        ranges[ranges > self.range_max] = np.inf
        ranges[ranges < self.range_min] = -np.inf
        return ranges


@functools.lru_cache(maxsize=16)
def _directions(lidar: Lidar) -> np.ndarray:
    """The beams' unit vectors in the sensor frame, computed once per lidar."""
    return raycast.directions(lidar.angles())
