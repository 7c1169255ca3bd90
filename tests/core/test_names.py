"""An exercise or quiz id nobody has reads as a missing name, with the one meant
(autograder/core/names.py): never as a path to a file that looks broken."""

from __future__ import annotations

import pytest
from click.testing import CliRunner

from autograder.cli import main
from autograder.core.names import suggest


@pytest.mark.parametrize(("name", "meant"), [
    ("parameter-validation", "parameter_validation"),  # a quiz's hyphens for an exercise
    ("Timer_Sync", "timer_sync"),
    ("paramter_validaton", "parameter_validation"),  # typos
    ("calback_groups", "callback_groups"),
    ("navigation", None),
])
def test_the_id_meant_is_suggested(name: str, meant: str | None) -> None:
    known = ["ai_bridge", "callback_groups", "error_handling", "parameter_validation",
             "timer_sync"]
    assert suggest(name, known) == meant


@pytest.mark.parametrize(("args", "expected"), [
    (["check", "parameter-validation", "x.py"],
     "No exercise named parameter-validation. Did you mean parameter_validation?"),
    (["start", "timer_synch"], "No exercise named timer_synch. Did you mean timer_sync?"),
    (["quiz", "take", "rclpy_part2"], "No quiz named rclpy_part2. Did you mean rclpy-part2?"),
    (["quiz", "take", "parameter_validation"],
     "No quiz named parameter_validation. Did you mean parameter-validation?"),
])
def test_a_mistyped_id_gets_a_did_you_mean(args: list[str], expected: str) -> None:
    result = CliRunner().invoke(main, args, input="")
    assert result.exit_code == 2, result.output
    assert result.output.strip() == f"Error: {expected}"


def test_an_unknown_exercise_names_what_is_missing_not_a_file() -> None:
    result = CliRunner().invoke(main, ["check", "navigation", "x.py"])
    assert result.exit_code == 2
    assert result.output.startswith("Error: No exercise named navigation; the exercises are ")
    assert "exercise.yaml" not in result.output and "/" not in result.output


def test_in_urdu_too() -> None:
    result = CliRunner().invoke(main, ["--lang", "ur", "check", "parameter-validation", "x.py"])
    assert result.exit_code == 2
    assert "parameter_validation" in result.output
    assert any("\u0600" <= c <= "\u06ff" for c in result.output)


@pytest.mark.parametrize(("item", "expected"), [
    ("parameter-validaton", "No exercise or quiz named parameter-validaton. Did you mean the "
                            "exercise parameter_validation or the quiz parameter-validation?"),
    ("rclpy_part", "No exercise or quiz named rclpy_part. Did you mean rclpy-part2?"),
])
def test_grade_batch_suggests_among_exercises_and_quizzes(tmp_path, item: str,
                                                          expected: str) -> None:
    result = CliRunner().invoke(main, ["grade-batch", item, str(tmp_path), "--csv",
                                       str(tmp_path / "g.csv")])
    assert result.exit_code == 2
    assert result.output.strip() == f"Error: {expected}"
