"""What ``validate`` requires of the README of an exercise that reads ``/scan``: one Python
block defining ``front_sector``, which, run on a real scan of this robot, finds a box
straight ahead (beam 0 is straight ahead here, REP 103), and the note that
``ranges[len(ranges)//2]`` is straight behind. A README example that points students at
the wrong beams sends every one of them into the wall."""

from __future__ import annotations

import math
import re
from collections.abc import Callable
from pathlib import Path
from typing import Any

from autograder.core.exercise import Exercise
from autograder.i18n import _
from autograder.i18n.tools import Problem

_BLOCK = re.compile(r"^```python\n(.*?)^```", re.S | re.M)
# The README teaches where the beams are: these are the words it does so with.
NOTES = ("`ranges[len(ranges)//2]`", "REP 103", "REP 117")
AHEAD = 0.6  # metres to the box's face


def reads_scan(exercise: Exercise) -> bool:
    return exercise.solution.exists() and "LaserScan" in exercise.solution.read_text(
        encoding="utf-8")


def check_scan_readme(exercise: Exercise, path: Path, text: str) -> list[Problem]:
    """The problems of one README of ``exercise`` (none when it does not read ``/scan``)."""
    if not reads_scan(exercise):
        return []
    problems = [Problem(path, None, _(
        "this exercise reads /scan: say where its beams are ({note} missing)").format(
        note=note)) for note in NOTES if note not in text]
    blocks = [(text[:m.start()].count("\n") + 2, m.group(1)) for m in _BLOCK.finditer(text)
              if "def front_sector" in m.group(1)]
    if len(blocks) != 1:
        return [*problems, Problem(path, None, _(
            "this exercise reads /scan: one Python block defines `front_sector` (found "
            "{count})").format(count=len(blocks)))]
    line, code = blocks[0]
    try:
        namespace: dict[str, Any] = {}
        exec(compile(code, str(path), "exec"), namespace)  # the course's own
        found = [_nearest(namespace["front_sector"], angle_min) for angle_min in (0.0, -math.pi)]
    except Exception as exc:  # any failure of the example is its problem
        return [*problems, Problem(path, line, _(
            "the `front_sector` example fails on a real scan: {error}").format(
            error=f"{type(exc).__name__}: {exc}"))]
    if any(value is None or abs(value - AHEAD) > 0.05 for value in found):
        problems.append(Problem(path, line, _(
            "the `front_sector` example misses a box {distance} m straight ahead (it found "
            "{found}): beam 0 is straight ahead on this robot").format(
            distance=AHEAD, found=", ".join(str(v) for v in found))))
    return problems


def _nearest(front_sector: Callable[[Any], Any], angle_min: float) -> float | None:
    """The nearest range ``front_sector`` gives for a scan with a box ahead, or None."""
    from sensor_msgs.msg import LaserScan

    from sim.lidar import Lidar
    from sim.physics import World
    from sim.worldfile import Box, load_world

    world = World(load_world("empty_room"))
    world.add_obstacle(Box(center=(3.0 + AHEAD + 0.05, 3.0), size=(0.1, 0.4), angle=0.0))
    lidar = Lidar(angle_min=angle_min)
    scan = LaserScan(angle_min=lidar.angle_min, angle_max=lidar.angle_max,
                     angle_increment=lidar.angle_increment, range_min=lidar.range_min,
                     range_max=lidar.range_max, ranges=[float(r) for r in lidar.scan(world)])
    sector = list(front_sector(scan))
    return round(min(sector), 3) if sector else None
