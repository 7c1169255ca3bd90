"""Quiz files: the shipped quizzes load, and every malformed file is one clear line."""

from __future__ import annotations

from pathlib import Path

import pytest
from click.testing import CliRunner
from quiz_course import QUIZ_COURSE

from autograder.cli.quiz import quiz_cli
from autograder.core.errors import ContentError
from autograder.quiz.catalog import list_quizzes, load_all
from autograder.quiz.model import load_quiz

REPO = Path(__file__).resolve().parents[2]

GOOD = """\
id: tiny
title: Tiny quiz
questions:
  - id: q1
    type: single
    text: Pick a
    options:
      - {id: a, text: A}
      - {id: b, text: B}
    answer: a
"""


def test_shipped_quizzes_load() -> None:
    files = load_all(QUIZ_COURSE)
    ids = {qf.quiz.id for qf in files}
    assert ids == {"rclpy-part2", "parameter-validation", "timer-synchronization",
                   "callback-groups", "error-handling"}
    part2 = next(qf.quiz for qf in files if qf.quiz.id == "rclpy-part2")
    assert len(part2.questions) == 5 and part2.pass_mark == 0.7
    for qf in files:
        assert 5 <= len(qf.quiz.questions) <= 8, qf.path
        assert all(q.explanation for q in qf.quiz.questions), qf.path
    types = {q.type for qf in files for q in qf.quiz.questions}
    assert types == {"single", "multiple", "true_false", "numeric", "ordering"}


def test_list_quizzes_for_autograder_list(course: Path) -> None:
    entries = list_quizzes()
    assert {e.id for e in entries} >= {"rclpy-part2"}
    assert all(e.title and e.languages == ("en", "ur") for e in entries)


BROKEN = [
    ("yaml-error", "id: x\ntitle: [unclosed\n", 3, "YAML error"),
    ("missing-field", GOOD.replace("    text: Pick a\n", ""), 4, "questions[q1].text: required"),
    ("unknown-type", GOOD.replace("type: single", "type: essay"), 5,
     "questions[q1].type: must be one of"),
    ("unknown-field", GOOD.replace("    answer: a", "    answr: a"), 10, "unknown field"),
    ("key-names-no-option", GOOD.replace("answer: a", "answer: c"), 10,
     "the key must be one option id"),
    ("duplicate-option", GOOD.replace("{id: b, text: B}", "{id: a, text: B}"), 9,
     "duplicate option id"),
    ("negative-tolerance", GOOD.replace("type: single", "type: numeric").replace(
        "    options:\n      - {id: a, text: A}\n      - {id: b, text: B}\n    answer: a",
        "    answer: 2\n    tolerance: -1"), 8, "tolerance must be"),
    ("ordering-key-incomplete", GOOD.replace("type: single", "type: ordering").replace(
        "answer: a", "answer: [a]"), 10, "every item in order"),
    ("pass-mark", GOOD.replace("questions:", "pass_mark: 70\nquestions:"), 3, "pass_mark"),
]


@pytest.mark.parametrize(("text", "line", "message"), [b[1:] for b in BROKEN],
                         ids=[b[0] for b in BROKEN])
def test_malformed_quiz_names_file_line_and_field(tmp_path: Path, text: str, line: int,
                                                  message: str) -> None:
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    with pytest.raises(ContentError) as info:
        load_quiz(path)
    assert str(info.value).startswith(f"{path}:{line}: ")
    assert message in str(info.value)


def test_malformed_quiz_in_cli_is_one_line_and_changes_nothing(course: Path) -> None:
    bad = course / "quizzes" / "part2-rclpy.yaml"
    bad.write_text(bad.read_text().replace("type: single", "type: essay", 1))
    out = course / "results.json"
    answers = course / "a.json"
    answers.write_text('{"quiz": "rclpy-part2", "answers": {}}')
    result = CliRunner().invoke(quiz_cli, ["score", "rclpy-part2", str(answers),
                                           "--results", str(out)])
    assert result.exit_code == 2
    assert "Traceback" not in result.output
    lines = result.output.strip().splitlines()
    assert len(lines) == 1
    assert "part2-rclpy.yaml:8: questions[callback-groups-purpose].type" in lines[0]
    assert not out.exists()


def test_unknown_quiz_id_is_an_error(course: Path) -> None:
    result = CliRunner().invoke(quiz_cli, ["key", "no-such-quiz"])
    assert result.exit_code == 2 and "No quiz named no-such-quiz" in result.output
