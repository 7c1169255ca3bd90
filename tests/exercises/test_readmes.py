"""What every exercise README teaches holds: its front-beam example finds the beam straight
ahead in a real scan, and its hand-run commands name the exercise's own world, file and
cmd_vel topic (in English and in Urdu alike)."""

from __future__ import annotations

import math
import re
from pathlib import Path

import pytest
from click.testing import CliRunner
from sensor_msgs.msg import LaserScan

from autograder.cli import main
from autograder.core.exercise import Exercise, list_exercises
from sim.lidar import Lidar
from sim.physics import World
from sim.worldfile import Box, load_world

EXERCISES = {e.id: e for e in list_exercises()}
READMES = [(e, lang) for e in sorted(EXERCISES) for lang in ("README.md", "README.ur.md")]
# The topic a student drives by hand: what the node reads its velocity commands from.
DRIVE_TOPIC = {"parameter_validation": "agent/cmd_vel"}
HAND_RUN = {"README.md": "### Trying your node by hand\n",
            "README.ur.md": "### اپنے نوڈ کو ہاتھ سے آزمانا\n"}
DRIVE = "autograder sim drive --topic {topic} --linear 0.3 --angular 0.5 --for 5"
CODE_BLOCK = re.compile(r"^```python\n(.*?)^```", re.S | re.M)
# A test module's world: pytest.mark.world("obstacles"), or WORLD = "corridor" beside it.
TEST_WORLD = re.compile(r'mark\.world\("([\w.]+)"\)|^WORLD = "([\w.]+)"', re.M)


def readme(exercise: str, name: str) -> str:
    return (EXERCISES[exercise].folder / name).read_text(encoding="utf-8")


def reads_scan(exercise: Exercise) -> bool:
    return "LaserScan" in exercise.solution.read_text(encoding="utf-8")


def graded_worlds(exercise: Exercise) -> set[str]:
    """The worlds an exercise is graded in: its own and those its test modules name."""
    named = {exercise.world}
    for module in (exercise.folder / "tests").rglob("test_*.py"):
        named |= {a or b for a, b in TEST_WORLD.findall(module.read_text(encoding="utf-8"))}
    return {f"mydir/{w}" if (exercise.folder / w).is_file() else w for w in named}


def front_sector_of(text: str):
    """The README's front_sector function, run from its own code block."""
    blocks = [b for b in CODE_BLOCK.findall(text) if "def front_sector" in b]
    assert len(blocks) == 1, "one code block defines front_sector"
    namespace: dict = {}
    exec(compile(blocks[0], "README", "exec"), namespace)
    return namespace["front_sector"]


def scan_of(lidar: Lidar, world: World) -> LaserScan:
    """What the bridge publishes for this lidar in this world (float32 fields)."""
    return LaserScan(angle_min=lidar.angle_min, angle_max=lidar.angle_max,
                     angle_increment=lidar.angle_increment, range_min=lidar.range_min,
                     range_max=lidar.range_max,
                     ranges=[float(r) for r in lidar.scan(world)])


def box_ahead(theta: float, distance: float = 0.6) -> World:
    """The empty room, the robot turned to ``theta``, a box's face ``distance`` ahead."""
    world = World(load_world("empty_room"))
    world.robot.angle = world.control.angle = theta
    centre = distance + 0.05
    world.add_obstacle(Box(center=(3.0 + centre * math.cos(theta),
                                   3.0 + centre * math.sin(theta)),
                           size=(0.1, 0.4), angle=theta))
    return world


SCANNING = [(e, name) for e, name in READMES if reads_scan(EXERCISES[e])]


def test_the_exercises_that_read_scan_are_the_three_we_teach_it_in():
    assert sorted({e for e, _ in SCANNING}) == ["ai_bridge", "callback_groups",
                                                "error_handling"]


@pytest.mark.parametrize(("exercise", "name"), SCANNING)
@pytest.mark.parametrize("angle_min", [0.0, -math.pi], ids=["0..2pi", "-pi..pi"])
@pytest.mark.parametrize("theta", [0.0, 2.5], ids=["east", "north-west"])
def test_the_front_sector_example_sees_the_box_ahead(exercise, name, angle_min, theta):
    front_sector = front_sector_of(readme(exercise, name))
    lidar = Lidar(angle_min=angle_min)
    scan = scan_of(lidar, box_ahead(theta))
    sector = front_sector(scan)
    assert min(sector) == pytest.approx(0.6, abs=0.05)  # the box, not a wall
    # Exactly the valid readings within +-30 degrees of straight ahead, wrapping round 0.
    half_beam = lidar.angle_increment / 2
    expected = [r for i, r in enumerate(scan.ranges)
                if abs(math.remainder(angle_min + i * lidar.angle_increment, math.tau))
                <= math.radians(30) + half_beam and lidar.range_min <= r <= lidar.range_max]
    assert sorted(sector) == sorted(expected) and len(expected) > 30


@pytest.mark.parametrize(("exercise", "name"), SCANNING)
def test_the_middle_beam_is_straight_behind_here(exercise, name):
    text = readme(exercise, name)
    assert "`ranges[len(ranges)//2]`" in text and "REP 103" in text and "REP 117" in text
    scan = scan_of(Lidar(), box_ahead(0.0))
    assert scan.ranges[len(scan.ranges) // 2] > 2.0  # the wall behind, not the box


def test_the_sector_leaves_out_nan_and_both_infinities():
    front_sector = front_sector_of(readme("error_handling", "README.md"))
    scan = scan_of(Lidar(), box_ahead(0.0))
    valid = len(front_sector(scan))
    scan.ranges[0], scan.ranges[1], scan.ranges[359] = math.nan, math.inf, -math.inf
    sector = front_sector(scan)
    assert len(sector) == valid - 3
    assert all(scan.range_min <= r <= scan.range_max for r in sector)


@pytest.mark.parametrize(("exercise", "name"), READMES)
def test_the_hand_run_commands_are_the_exercises_own(exercise, name):
    found = EXERCISES[exercise]
    text = readme(exercise, name)
    runs = re.findall(r"autograder sim run --world (\S+) --node (\S+)", text)
    assert runs, "no hand run with --node"
    for world, node in runs:
        assert world in graded_worlds(found) and node == f"mydir/{found.file}", (world, node)
    assert DRIVE.format(topic=DRIVE_TOPIC.get(exercise, "cmd_vel")) in text
    assert HAND_RUN[name] in text


def test_start_copies_the_world_the_readme_names(tmp_path: Path):
    for exercise in ("timer_sync", "callback_groups", "parameter_validation"):
        found = EXERCISES[exercise]
        target = tmp_path / exercise / "mydir"
        result = CliRunner().invoke(main, ["start", exercise, str(target)])
        assert result.exit_code == 0, result.output
        for world in graded_worlds(found):
            if world.startswith("mydir/"):
                assert load_world(target.parent / world).name  # it is there, and it loads
        copied = sorted(p.name for p in target.iterdir())
        assert {found.file, "README.md", "README.ur.md"} == {
            n for n in copied if not n.endswith(".yaml")}
        assert len(copied) == 3 + any(w.startswith("mydir/") for w in graded_worlds(found))


def _graded_tests(exercise: Exercise) -> list[tuple[str, str, int, str]]:
    """(name, label, points, visibility) of each test, read from the test files."""
    import ast

    found = []
    for path in sorted((exercise.folder / "tests").glob("*/test_*.py")):
        for node in ast.parse(path.read_text(encoding="utf-8")).body:
            if isinstance(node, ast.FunctionDef) and node.name.startswith("test"):
                points = next(d.args[0].value for d in node.decorator_list
                              if isinstance(d, ast.Call)
                              and getattr(d.func, "attr", "") == "points")
                label = (ast.get_docstring(node) or "").splitlines()[0].strip()
                found.append((node.name, label, points, path.parent.name))
    return found


def _grading_table(text: str) -> list[list[str]]:
    """The cells of each row of the README's grading table (the one headed "| test |")."""
    lines = text.splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith("| test |"))
    rows = []
    for line in lines[start + 2:]:
        if not line.startswith("|"):
            break
        rows.append([cell.strip() for cell in line.strip().strip("|").split("|")])
    return rows


@pytest.mark.parametrize("exercise,name", READMES)
def test_the_grading_table_is_the_tests_labels_points_visibility_and_core(exercise, name):
    """Each row of a README's grading table is a test as a student sees it graded: its label
    (in the README's language; code spans aside), its points, public or hidden, and whether
    it is core; every test has its row."""
    from autograder.i18n import _, set_language

    core_mark = {"README.md": "**core**", "README.ur.md": "**بنیادی**"}[name]
    set_language("ur" if name == "README.ur.md" else "en")
    try:
        wanted = sorted((_(label).replace("`", ""), str(points),
                         "public" if folder == "public" else "hidden",
                         core_mark if test in EXERCISES[exercise].core else "")
                        for test, label, points, folder in _graded_tests(EXERCISES[exercise]))
    finally:
        set_language("en")
    # A fifth cell, each test's simulation seconds, is the proofs' to check (tests/proving.py).
    rows = sorted((cells[0].replace("`", ""), *cells[1:4]) for cells in _grading_table(
        readme(exercise, name)))
    assert [tuple(r) for r in rows] == [tuple(w) for w in wanted]
