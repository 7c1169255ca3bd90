"""Recording of a run: the trajectory at every odometry sample, every collision, the
commands the world received and its scans, for a report to draw and replay.

Kept apart from physics and ROS so a report can be built from plain data; importing it
loads neither numpy nor pymunk, as the grader reads every grading's recordings.  In
memory a scan is kept at most every ``scan_period`` of sim time (2 Hz), so a long run
stays small; :meth:`Recording.to_dict` also bounds what it writes (see its docstring).
"""

from __future__ import annotations

import array
import itertools
import math
import threading
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from sim.contact import Contact

if TYPE_CHECKING:  # numpy is imported by the first scan kept: reading a recording needs none
    import numpy as np

# to_dict's bounds, chosen so a module's recording stays under about 240 KB of JSON
# whatever the run's length (a trajectory row is ~47 bytes, a 360-beam scan ~1.5 KB).
MAX_TRAJECTORY_ROWS = 1500  # 30 s at 50 Hz; a longer run keeps samples evenly spread
MAX_COMMAND_ROWS = 1000  # changes of command; more are thinned evenly
SCAN_BUDGET = 130_000  # bytes of scans in the JSON; fewer scans, evenly spaced, beyond it
SCAN_PERIOD = 0.5  # sim seconds between the scans kept in memory (2 Hz)
MAX_SCANS_KEPT = 2400  # 20 min at 2 Hz (3.5 MB); beyond, every other goes, the period doubles


@dataclass(frozen=True)
class Sample:
    """One odometry sample: sim time, pose and body-frame velocities."""

    t: float
    x: float
    y: float
    theta: float
    v: float
    w: float


@dataclass(frozen=True)
class Command:
    """A velocity command the world received, in force from sim time ``t``."""

    t: float
    linear: float
    angular: float


@dataclass(frozen=True)
class ScanRecord:
    """A scan as it went out (faults included): ranges in metres (float32), inf where
    none; a faulty scan may have more or fewer ranges than beams."""

    t: float
    ranges: array.array[float]


@dataclass
class Recording:
    """Everything recorded in one run; thread safe to append to and read."""

    world: str = ""
    samples: list[Sample] = field(default_factory=list)
    collisions: list[Contact] = field(default_factory=list)
    commands: list[Command] = field(default_factory=list)
    scans: list[ScanRecord] = field(default_factory=list)
    scan_angle_min: float = 0.0  # the scanner's geometry, in the robot's frame
    scan_angle_increment: float = 2 * math.pi / 360
    scan_period: float = SCAN_PERIOD
    _lock: threading.Lock = field(default_factory=threading.Lock, repr=False, compare=False)
    _spread: int = field(default=1, repr=False, compare=False)  # doubles when scans are thinned

    def add_sample(self, sample: Sample) -> None:
        with self._lock:
            self.samples.append(sample)

    def add_collision(self, contact: Contact) -> None:
        with self._lock:
            self.collisions.append(contact)

    def add_command(self, t: float, linear: float, angular: float) -> None:
        """A command the world received at sim time ``t`` (a repeat of the one in force
        is not kept: it changes nothing a replay shows)."""
        with self._lock:
            last = self.commands[-1] if self.commands else None
            if last is None or (last.linear, last.angular) != (linear, angular):
                self.commands.append(Command(t, linear, angular))

    def add_scan(self, t: float, ranges: Sequence[float] | np.ndarray) -> None:
        """A scan published at sim time ``t``, kept if ``scan_period`` has passed since the
        last one kept."""
        with self._lock:
            if self.scans and t - self.scans[-1].t < self.scan_period * self._spread - 1e-9:
                return
            import numpy as np

            raw = np.asarray(ranges, dtype=np.float32).tobytes()
            self.scans.append(ScanRecord(t, array.array("f", raw)))
            if len(self.scans) > MAX_SCANS_KEPT:
                del self.scans[1::2]
                self._spread *= 2

    def clear(self) -> None:
        with self._lock:
            self.samples.clear()
            self.collisions.clear()
            self.commands.clear()
            self.scans.clear()
            self._spread = 1

    def snapshot(self) -> tuple[list[Sample], list[Contact]]:
        """Copies of the samples and collisions so far."""
        with self._lock:
            return list(self.samples), list(self.collisions)

    def replay_snapshot(self) -> tuple[list[Command], list[ScanRecord]]:
        """Copies of the commands and scans so far."""
        with self._lock:
            return list(self.commands), list(self.scans)

    def distance(self) -> float:
        """Path length travelled (m)."""
        samples, _ = self.snapshot()
        return sum(math.dist((a.x, a.y), (b.x, b.y))
                   for a, b in itertools.pairwise(samples))

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready form: {world, fields, trajectory: [[t, x, y, theta, v, w], ...],
        collisions, commands: [[t, linear, angular], ...], scan: {angle_min,
        angle_increment}, scans: [[t, [range, ...]], ...]}.

        Bounded whatever the run's length: poses to 0.1 mm and 0.1 mrad, at most
        MAX_TRAJECTORY_ROWS samples (evenly thinned, the last kept); commands to 1e-3, at
        most MAX_COMMAND_ROWS; scans at 2 Hz or fewer so they fit SCAN_BUDGET bytes, ranges
        to 0.01 m with ``null`` for no reading (inf, -inf, NaN).
        """
        samples, collisions = self.snapshot()
        commands, scans = self.replay_snapshot()
        return {
            "world": self.world,
            "fields": ["t", "x", "y", "theta", "v", "w"],
            "trajectory": [[round(s.t, 3), round(s.x, 4), round(s.y, 4), round(s.theta, 4),
                            round(s.v, 3), round(s.w, 3)]
                           for s in _thin(samples, MAX_TRAJECTORY_ROWS)],
            "collisions": [{"t": c.t, "x": c.x, "y": c.y, "what": c.what} for c in collisions],
            "commands": [[round(c.t, 3), round(c.linear, 3), round(c.angular, 3)]
                         for c in _thin(commands, MAX_COMMAND_ROWS)],
            "scan": {"angle_min": self.scan_angle_min,
                     "angle_increment": self.scan_angle_increment},
            "scans": _scans_within(scans, SCAN_BUDGET),
        }

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> Recording:
        """The inverse of :meth:`to_dict` (to its precision); a recording written before
        commands and scans were kept reads back without them."""
        scan = data.get("scan", {})
        return cls(world=data.get("world", ""),
                   samples=[Sample(*row) for row in data.get("trajectory", [])],
                   collisions=[Contact(**c) for c in data.get("collisions", [])],
                   commands=[Command(*row) for row in data.get("commands", [])],
                   scans=[ScanRecord(t, array.array("f", [math.inf if r is None else r
                                                          for r in ranges]))
                          for t, ranges in data.get("scans", [])],
                   scan_angle_min=scan.get("angle_min", 0.0),
                   scan_angle_increment=scan.get("angle_increment", 2 * math.pi / 360))


def _thin(rows: list[Any], most: int) -> list[Any]:
    """At most ``most`` of ``rows``, evenly spaced, the first and the last kept."""
    if len(rows) <= most:
        return rows
    step = (len(rows) - 1) / (most - 1)
    return [rows[round(i * step)] for i in range(most)]


def _range(r: float) -> float | None:
    return round(r, 2) if math.isfinite(r) else None


def _scans_within(scans: list[ScanRecord], budget: int) -> list[list[Any]]:
    """The scans as JSON rows; evenly thinned until their text fits ``budget`` bytes."""
    rows = [[round(s.t, 3), [_range(r) for r in s.ranges]] for s in scans]
    size = sum(len(str(row)) for row in rows)  # close to json.dumps's compact size
    if size <= budget:
        return rows
    return _thin(rows, max(2, len(rows) * budget // size))
