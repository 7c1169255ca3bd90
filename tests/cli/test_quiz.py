"""``autograder quiz take`` in a terminal, and the list command."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from click.testing import CliRunner
from quiz_course import QUIZ_COURSE

from autograder.cli.quiz import quiz_cli
from autograder.quiz.model import load_quiz
from autograder.quiz.render import question_views

REPO = Path(__file__).resolve().parents[2]
ERRORS = load_quiz(QUIZ_COURSE / "quizzes" / "error-handling.yaml").quiz


pytestmark = pytest.mark.usefixtures("in_quiz_course")


def _right_input(seed: str) -> str:
    """What a student who knows every answer types, for this seed's option order."""
    lines = []
    for view in question_views(ERRORS, "en", seed):
        q = ERRORS.question(view.id)
        positions = {o.id: str(i) for i, o in enumerate(view.options, 1)}
        key = q.key()
        if isinstance(key, list):
            lines.append((" " if q.type == "ordering" else ",").join(positions[k] for k in key))
        else:
            lines.append(positions[key])
    return "\n".join(lines) + "\n"


def test_take_in_english_saves_a_scorable_answers_file(tmp_path: Path) -> None:
    save = tmp_path / "answers.json"
    result = CliRunner().invoke(quiz_cli, ["take", "error-handling", "--seed", "5",
                                           "--save", str(save)], input=_right_input("5"))
    assert result.exit_code == 0, result.output
    assert "Passed: 6 of 6 (100%)" in result.output
    saved = json.loads(save.read_text())
    assert saved["quiz"] == "error-handling" and saved["seed"] == "5"
    scored = CliRunner().invoke(quiz_cli, ["score", "error-handling", str(save), "--json"])
    assert json.loads(scored.output)["passed"] is True


def test_take_reprompts_on_nonsense_and_skips_on_enter() -> None:
    result = CliRunner().invoke(quiz_cli, ["take", "rclpy-part2", "--seed", "1"],
                                input="9\nabc\n\n\n\n\n\n")
    assert result.exit_code == 0, result.output
    assert result.output.count("That is not an answer to this question") == 2
    assert "Not passed yet: 0 of 5 (0%)" in result.output


def test_take_in_urdu_points_to_the_page() -> None:
    result = CliRunner().invoke(quiz_cli, ["take", "rclpy-part2", "--lang", "ur"],
                                input="\n" * 5)
    assert result.exit_code == 0, result.output
    assert "autograder quiz serve" in result.output
    assert "rclpy میں callback groups کا بنیادی مقصد کیا ہے؟" in result.output
    assert "کامیابی کے لیے درکار اسکور: 70% (4/5 سوالات)" in result.output


def test_list_json() -> None:
    result = CliRunner().invoke(quiz_cli, ["list", "--json"])
    data = json.loads(result.output)
    assert {"id": "rclpy-part2", "title": "Part 2 quiz: Python and ROS 2 with rclpy",
            "languages": ["en", "ur"]} in data
