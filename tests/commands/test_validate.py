"""Bad authoring input gets an error naming the file and what is wrong; `autograder
validate` checks a whole course tree."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from click.testing import CliRunner

from autograder.cli import main
from autograder.commands.validate import validate
from autograder.core.exercise import load_exercise
from autograder.grading.run import GRADER_FAULT, grade

MINI = Path(__file__).parents[1] / "fixtures" / "mini_course"


@pytest.fixture
def course(tmp_path: Path, monkeypatch) -> Path:
    root = tmp_path / "course"
    shutil.copytree(MINI, root)
    monkeypatch.setenv("AUTOGRADER_COURSE", str(root))
    return root


def shout(course: Path) -> Path:
    return course / "assignments" / "shout"


@pytest.mark.slow
def test_a_sound_course_validates(course):
    assert [str(p) for p in validate(course)] == []
    result = CliRunner().invoke(main, ["validate", "--no-grade", "--course", str(course)])
    assert result.exit_code == 0 and "The course is valid." in result.output


def test_missing_files_and_bad_worlds_are_named(course):
    (shout(course) / "starter" / "shouter.py").unlink()
    other = course / "assignments" / "broken"
    shutil.copytree(shout(course), other)
    text = (other / "exercise.yaml").read_text().replace("id: shout", "id: broken")
    (other / "exercise.yaml").write_text(text + "world: no_such_world\n")
    third = course / "assignments" / "typo"
    shutil.copytree(shout(course), third)
    (third / "exercise.yaml").write_text("id: typo\ntitle: T\nfile: a.py\nnode: a\n"
                                         "pass_mark: 0.7\nponits: 3\n")
    (course / "assignments" / "empty").mkdir()
    problems = [str(p) for p in validate(course, run_gradings=False)]
    assert any("shout/exercise.yaml" in p and "starter file" in p for p in problems)
    assert any(p.startswith(f"{other / 'exercise.yaml'}:") and "world: unknown world "
               "'no_such_world'" in p for p in problems), problems
    assert any(p.startswith(f"{third / 'exercise.yaml'}:6: ponits: unknown field")
               for p in problems), problems
    assert any(f"{course / 'assignments' / 'empty'}:1: no exercise.yaml" in p for p in problems)
    result = CliRunner().invoke(main, ["validate", "--no-grade", "--course", str(course)])
    assert result.exit_code == 1 and "problems found" in result.output


@pytest.mark.slow
def test_a_failing_reference_and_a_passing_starter_are_caught(course):
    folder = shout(course)
    solution = (folder / "solution" / "shouter.py").read_text()
    (folder / "solution" / "shouter.py").write_text(solution.replace("msg.data.upper()",
                                                                     "msg.data"))
    (folder / "starter" / "shouter.py").write_text(solution)
    problems = [str(p) for p in validate(course)]
    assert any("the reference solution scores 2/3" in p for p in problems), problems
    assert any("the reference solution fails core tests: test_upper_case" in p
               for p in problems), problems
    assert any("the starter scores 3/3, at or above the pass mark" in p for p in problems)
    assert any("the starter passes every core test (test_upper_case)" in p for p in problems)


def test_core_tests_must_be_named_and_exist(course):
    path = shout(course) / "exercise.yaml"
    text = path.read_text()
    path.write_text(text.replace("core: [test_upper_case]",
                                 "core:\n  - test_upper_case\n  - test_uper_case"))
    problems = [str(p) for p in validate(course, run_gradings=False)]
    line = text.splitlines().index("core: [test_upper_case]") + 3
    assert any(p.startswith(f"{path}:{line}: core.1: no test named 'test_uper_case'")
               for p in problems), problems
    assert not any("'test_upper_case'" in p for p in problems), problems
    path.write_text(text.replace("core: [test_upper_case]\n", ""))
    problems = [str(p) for p in validate(course, run_gradings=False)]
    assert any(p.startswith(f"{path}:") and "core names no test" in p for p in problems)


def test_malformed_exercise_file_names_file_line_and_field(course):
    (shout(course) / "exercise.yaml").write_text("id: shout\ntitle: [unclosed\n")
    with pytest.raises(Exception) as caught:
        load_exercise(shout(course))
    assert str(caught.value).startswith(f"{shout(course) / 'exercise.yaml'}:")
    result = CliRunner().invoke(main, ["check", "shout", str(course)])
    assert result.exit_code == 2 and "exercise.yaml:" in result.output
    assert "Traceback" not in result.output


def test_cmd_vel_type_is_the_worlds_unless_the_exercise_says(course):
    assert load_exercise(shout(course)).cmd_vel_type is None  # the world's (Twist)
    path = shout(course) / "exercise.yaml"
    text = path.read_text()
    path.write_text(text + "cmd_vel_type: TwistStamped\n")
    assert load_exercise(shout(course)).cmd_vel_type == "TwistStamped"
    path.write_text(text + "cmd_vel_type: twist\n")
    problems = [str(p) for p in validate(course, run_gradings=False)]
    line = len(text.splitlines()) + 1
    assert any(p.startswith(f"{path}:{line}: cmd_vel_type: must be one of 'Twist', "
                            "'TwistStamped'") for p in problems), problems


@pytest.mark.slow
@pytest.mark.parametrize("broken,where", [
    ("def test_x(:\n    pass\n", "test_broken.py"),                      # does not import
    ("def test_x(student):\n    {}['missing']\n", "test_broken.py"),     # raises inside
])
def test_a_broken_exercise_test_is_a_grader_error_naming_the_file(course, broken, where):
    (shout(course) / "tests" / "public" / "test_broken.py").write_text(broken)
    exercise = load_exercise(shout(course))
    result = grade(exercise, None)
    assert result.grader_error == GRADER_FAULT
    assert where in result.grader_details


@pytest.mark.slow
def test_check_runs_public_tests_only_without_a_grader_fault(course, tmp_path):
    """The public tests carry fewer points than the exercise: that is no fault."""
    out = tmp_path / "results.json"
    result = CliRunner().invoke(main, ["check", "shout", str(shout(course) / "solution"),
                                       "--results", str(out)])
    assert result.exit_code == 0, result.output
    data = __import__("json").loads(out.read_text())
    assert data["grader_error"] is None
    assert (data["score"], data["max_score"]) == (2, 2)
    assert {t["visibility"] for t in data["tests"]} == {"visible"}
