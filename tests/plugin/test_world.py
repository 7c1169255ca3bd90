"""The fixtures of the graph a test runs on, in an inner pytest run as grading runs one: the
exercise (skipped without the grader's settings), a staged copy of the student's file (a
missing one is the student's failure), the run's rclpy context on its ROS domain, the world
a module's marker picks (an exercise's own world file by path) kept where the reporter
finds it, and the probe on the same graph; each module's recording and pacing reported."""

from __future__ import annotations

import shutil
import textwrap
from pathlib import Path

import pytest

from autograder.core.settings import RunSettings
from autograder.core.signing import verify

MINI = Path(__file__).resolve().parents[1] / "fixtures" / "mini_course" / "assignments" / "shout"
WALL = 300

INNER = '''
    import os
    import pytest
    from autograder.plugin.probe import WORLD_NODE_NAME
    from autograder.plugin.stash import world_key

    pytestmark = pytest.mark.world({world!r})  # the module's world

    def test_staged_copy(exercise, submission_file):
        assert exercise.id == "shout"
        assert submission_file.name == "shouter.py"
        assert submission_file.read_text() == {source!r}
        assert str(submission_file) != {given!r}  # a private copy, not the student's file

    def test_context_on_the_runs_domain(ros_context):
        assert ros_context.ok()
        assert ros_context.get_domain_id() == int(os.environ["ROS_DOMAIN_ID"]) == {domain}

    def test_world_and_probe(request, world, probe):
        assert world.world.spec.name == {world_name!r}
        assert request.config.stash[world_key] is world
        assert WORLD_NODE_NAME in probe.node.get_node_names()
'''


def _run(pytester: pytest.Pytester, tmp_path: Path, domain: int, submission: Path,
         world: str = "wall_ahead", world_name: str = "wall_ahead") -> tuple[dict, dict]:
    exercise = tmp_path / "course" / "assignments" / "shout"
    shutil.copytree(MINI, exercise)
    (exercise / "own_room.yaml").write_text("size: [5, 5]\nstart: {x: 1, y: 1}\n")
    tests = pytester.path / "test_inner.py"
    source = submission.read_text() if submission.is_file() else ""
    tests.write_text(textwrap.dedent(INNER.format(
        source=source, given=str(submission), domain=domain, world=world,
        world_name=world_name)))
    report = tmp_path / "report.json"
    settings = RunSettings(exercise=str(exercise), submission=str(submission),
                           report=str(report), domain=domain)
    result = pytester.runpytest_subprocess("-p", "no:cacheprovider", "--autograder-settings",
                                           settings.to_json(), str(tests), timeout=WALL)
    data = verify(report.read_text(), b"")
    return ({entry["name"]: entry for entry in data["tests"]},
            {**data["data"], "stdout": result.outlines})


def test_without_the_graders_settings_the_fixtures_skip(pytester: pytest.Pytester) -> None:
    pytester.makepyfile("def test_needs(exercise):\n    pass\n")
    result = pytester.runpytest("-p", "no:cacheprovider", "-rs")
    result.assert_outcomes(skipped=1)
    result.stdout.fnmatch_lines(["*run with --exercise to use the autograder fixtures*"])


def test_the_graph_fixtures_of_a_grading_run(pytester: pytest.Pytester, tmp_path: Path,
                                            ros_domain: int) -> None:
    solution = MINI / "solution" / "shouter.py"
    tests, data = _run(pytester, tmp_path, ros_domain, solution)
    assert {name: t["status"] for name, t in tests.items()} == {
        "test_staged_copy": "passed", "test_context_on_the_runs_domain": "passed",
        "test_world_and_probe": "passed"}, data["stdout"]
    # The module's world is recorded and its pacing kept, by the module's name.
    assert list(data["recordings"]) == ["test_inner.py"]
    assert data["recordings"]["test_inner.py"]["world"] == "wall_ahead"
    assert "longest_hold" in data["pacing"]["test_inner.py"]


def test_an_exercises_own_world_file_and_a_missing_submission(
        pytester: pytest.Pytester, tmp_path: Path, ros_domain: int) -> None:
    tests, data = _run(pytester, tmp_path, ros_domain, tmp_path / "nothing_here",
                       world="own_room.yaml", world_name="own_room")
    staged = tests["test_staged_copy"]
    assert staged["status"] == "failed", data["stdout"]  # the student's failure, not ours
    assert "nothing_here" in staged["message"]
    assert tests["test_world_and_probe"]["status"] == "passed", data["stdout"]
