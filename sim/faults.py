"""Fault injection: corrupted, malformed or missing scans, and obstacles that appear.

Faults come from the world file's ``faults:`` list or are added at run time; each is a
:class:`sim.worldfile.Fault` active over ``[start, end)`` in sim time.  What each kind
does is in :data:`sim.faultkinds.KINDS`; this module applies them in time.  Faults that
pick beams draw them from a generator seeded by (world seed, fault index, scan time), so
a run is reproducible whatever the order or pace of the calls.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from sim.faultkinds import KINDS, ScanDraft
from sim.lidar import Lidar
from sim.worldfile import Box, Circle, Fault


@dataclass(frozen=True)
class Scan:
    """What goes out on /scan: ranges may be shorter than the beam count on purpose."""

    t: float
    ranges: np.ndarray
    intensities: np.ndarray


def nan_readings(start: float, end: float | None = None, fraction: float = 0.1) -> Fault:
    """A share of beams reads NaN over [start, end)."""
    return Fault(kind="nan", start=start, end=end, fraction=fraction)


def obstacle_at(start: float, obstacle: Box | Circle) -> Fault:
    """``obstacle`` appears at sim time ``start``."""
    if isinstance(obstacle, Box):
        return Fault(kind="obstacle", start=start, box=obstacle)
    return Fault(kind="obstacle", start=start, circle=obstacle)


def _active(fault: Fault, t: float) -> bool:
    return fault.start <= t and (fault.end is None or t < fault.end)


class FaultInjector:
    """Applies a list of faults to scans and tells when obstacles are due."""

    def __init__(self, faults: tuple[Fault, ...] | list[Fault] = (), seed: int = 0,
                 lidar: Lidar | None = None) -> None:
        self.faults: list[Fault] = list(faults)
        self.seed = seed
        self.lidar = lidar or Lidar()
        self._placed: set[int] = set()
        self.obstacles_pending = self._any_obstacle_pending()
        """Whether an obstacle is yet to be placed: the simulation asks every step."""

    def add(self, fault: Fault) -> None:
        """Add a fault at run time (it takes effect from its ``start``)."""
        if fault.kind not in KINDS:
            raise ValueError(f"unknown fault kind {fault.kind!r}")
        self.faults.append(fault)
        self.obstacles_pending = self._any_obstacle_pending()

    def reset(self) -> None:
        """Forget which obstacles were placed (the world was rebuilt)."""
        self._placed.clear()
        self.obstacles_pending = self._any_obstacle_pending()

    def due_obstacles(self, t: float) -> list[Box | Circle]:
        """Obstacles whose time has come and that were not placed yet."""
        due: list[Box | Circle] = []
        placed = len(self._placed)
        for i, fault in enumerate(self.faults):
            places = KINDS[fault.kind].places
            if places is not None and i not in self._placed and fault.start <= t:
                self._placed.add(i)
                obstacle = places(fault)
                if obstacle is not None:
                    due.append(obstacle)
        if len(self._placed) != placed:
            self.obstacles_pending = self._any_obstacle_pending()
        return due

    def _any_obstacle_pending(self) -> bool:
        return any(KINDS[fault.kind].places is not None and i not in self._placed
                   for i, fault in enumerate(self.faults))

    def apply(self, t: float, ranges: np.ndarray) -> Scan | None:
        """The scan to publish at ``t`` from clean ``ranges``, or None during a dropout."""
        scan = ScanDraft(ranges.astype(np.float32), len(ranges), self.lidar)
        for i, fault in enumerate(self.faults):
            effect = KINDS[fault.kind].on_scan
            if effect is not None and _active(fault, t):
                effect(scan, fault, functools.partial(self._pick, i, t, scan.beams))
        if scan.dropped:
            return None
        out = scan.ranges
        if scan.length != scan.beams:
            out = np.resize(out, scan.length)  # repeats readings when asked for more
        return Scan(t, out, np.full(scan.length, 100.0, dtype=np.float32))

    def _pick(self, index: int, t: float, beams: int, fraction: float) -> np.ndarray:
        rng = np.random.default_rng([self.seed, index, round(t * 1e6)])
        count = round(beams * fraction)
        return rng.choice(beams, size=count, replace=False)
