"""validate's check of a /scan exercise's README (autograder/commands/scan_readme.py): its
`front_sector` example, run on a real scan of this robot, finds the box straight ahead."""

from __future__ import annotations

import dataclasses
import shutil
from pathlib import Path

import pytest

from autograder.commands.scan_readme import NOTES, check_scan_readme
from autograder.core.exercise import Exercise, load_exercise

MINI = Path(__file__).parents[1] / "fixtures" / "mini_course" / "assignments" / "shout"

RIGHT = '''
import math

def front_sector(scan, half_width=math.radians(30)):
    """Valid ranges within half_width of straight ahead (beam 0, REP 103)."""
    found = []
    for i, r in enumerate(scan.ranges):
        angle = math.remainder(scan.angle_min + i * scan.angle_increment, math.tau)
        if abs(angle) <= half_width and scan.range_min <= r <= scan.range_max:
            found.append(r)
    return found
'''
# The book's "front": the middle beam, which is straight behind on this robot.
MIDDLE = '''
def front_sector(scan):
    middle = len(scan.ranges) // 2
    return [r for r in scan.ranges[middle - 30:middle + 30] if r > scan.range_min]
'''


def readme(code: str | None, notes: bool = True) -> str:
    text = "# Avoider\n\n" + (" ".join(NOTES) + "\n\n" if notes else "")
    return text + (f"```python\n{code.strip()}\n```\n" if code is not None else "")


@pytest.fixture
def exercise(tmp_path: Path) -> Exercise:
    folder = tmp_path / "shout"
    shutil.copytree(MINI, folder)
    solution = folder / "solution" / "shouter.py"
    solution.write_text("from sensor_msgs.msg import LaserScan\n" + solution.read_text())
    return dataclasses.replace(load_exercise(folder), folder=folder)


def test_the_example_that_finds_the_box_ahead_passes(exercise: Exercise, tmp_path: Path) -> None:
    assert check_scan_readme(exercise, tmp_path / "README.md", readme(RIGHT)) == []


def test_the_middle_beam_example_is_caught_at_its_block(exercise: Exercise,
                                                        tmp_path: Path) -> None:
    found = [str(p) for p in check_scan_readme(exercise, tmp_path / "README.md",
                                               readme(MIDDLE))]
    assert len(found) == 1 and found[0].startswith(f"{tmp_path / 'README.md'}:6: ")
    assert "misses a box 0.6 m straight ahead" in found[0]


def test_a_missing_example_or_note_is_named(exercise: Exercise, tmp_path: Path) -> None:
    found = [str(p) for p in check_scan_readme(exercise, tmp_path / "README.md",
                                               readme(None, notes=False))]
    assert len(found) == len(NOTES) + 1
    assert "one Python block defines `front_sector` (found 0)" in found[-1]


def test_an_exercise_that_does_not_read_scan_needs_none(tmp_path: Path) -> None:
    shout = load_exercise(MINI)
    assert check_scan_readme(shout, tmp_path / "README.md", readme(None, notes=False)) == []
