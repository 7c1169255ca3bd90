"""Scoring: exact arithmetic at and around the pass mark, every question type, answers files."""

from __future__ import annotations

import json
from fractions import Fraction
from pathlib import Path

import pytest
from click.testing import CliRunner
from quiz_course import QUIZ_COURSE

from autograder.cli.quiz import quiz_cli
from autograder.core.errors import ContentError
from autograder.quiz.catalog import load_all
from autograder.quiz.model import load_quiz
from autograder.quiz.scoring import key_answers, pass_summary, read_answers, score

REPO = Path(__file__).resolve().parents[2]
PART2 = QUIZ_COURSE / "quizzes" / "part2-rclpy.yaml"


pytestmark = pytest.mark.usefixtures("in_quiz_course")


def _quiz(n: int, pass_mark: str = "") -> object:
    """n single-choice questions q0..q{n-1}, key 'a'."""
    questions = "".join(
        f"  - id: q{i}\n    text: Q{i}\n    options: [{{id: a, text: A}}, {{id: b, text: B}}]\n"
        f"    answer: a\n" for i in range(n))
    return load_quiz("n.yaml", f"id: n\ntitle: N\n{pass_mark}questions:\n{questions}").quiz


@pytest.mark.parametrize(("right", "total", "passed"), [
    (4, 5, True), (3, 5, False), (5, 5, True), (0, 5, False),
    (7, 10, True), (6, 10, False),
], ids=["4-of-5-passes", "3-of-5-fails", "5-of-5", "0-of-5", "7-of-10-at-the-mark",
        "6-of-10-fails"])
def test_pass_mark_is_exact(right: int, total: int, passed: bool) -> None:
    quiz = _quiz(total)
    answers = {f"q{i}": "a" if i < right else "b" for i in range(total)}
    result = score(quiz, answers)
    assert result.score == right and result.max_score == total
    assert result.passed is passed
    assert result.pass_mark == Fraction(7, 10)
    data = result.to_dict()
    assert (data["score"], data["max_score"], data["passed"]) == (right, total, passed)
    assert [t["name"] for t in data["tests"]] == [f"q{i}" for i in range(total)]


def test_quiz_can_set_its_own_pass_mark() -> None:
    quiz = _quiz(5, "pass_mark: 0.8\n")
    assert not score(quiz, {f"q{i}": "a" for i in range(3)}).passed
    assert score(quiz, {f"q{i}": "a" for i in range(4)}).passed


def test_left_out_question_scores_zero() -> None:
    result = score(_quiz(2), {"q0": "a"})
    assert [t.score for t in result.tests] == [1, 0]
    assert result.tests[1].message == "Not answered."


def test_pass_summary_in_both_languages() -> None:
    quiz = load_quiz(PART2).quiz
    assert pass_summary(quiz, "en") == "Passing score: 70% (4/5 questions)"
    assert pass_summary(quiz, "ur") == "کامیابی کے لیے درکار اسکور: 70% (4/5 سوالات)"
    assert pass_summary(_quiz(1), "en") == "Passing score: 70% (1/1 question)"


TYPES = """\
id: types
title: Types
questions:
  - id: tf
    type: true_false
    text: T?
    answer: false
  - id: num
    type: numeric
    text: N?
    answer: 0.3
    tolerance: 0.05
  - id: all-or-nothing
    type: multiple
    text: M?
    options: [{id: a, text: A}, {id: b, text: B}, {id: c, text: C}]
    answer: [a, b]
  - id: partial
    type: multiple
    partial_credit: true
    points: 2
    text: P?
    options: [{id: a, text: A}, {id: b, text: B}, {id: c, text: C}]
    answer: [a, b]
  - id: order
    type: ordering
    text: O?
    options: [{id: x, text: X}, {id: y, text: Y}, {id: z, text: Z}]
    answer: [x, y, z]
"""


@pytest.mark.parametrize(("question", "answer", "earned"), [
    ("tf", "false", 1), ("tf", False, 1), ("tf", "true", 0),
    ("num", 0.3, 1), ("num", 0.35, 1), ("num", 0.25, 1), ("num", 0.36, 0), ("num", 1, 0),
    ("all-or-nothing", ["a", "b"], 1), ("all-or-nothing", ["b", "a"], 1),
    ("all-or-nothing", ["a"], 0), ("all-or-nothing", ["a", "b", "c"], 0),
    ("partial", ["a", "b"], 2), ("partial", ["a"], 1), ("partial", ["a", "c"], 0),
    ("partial", ["c"], 0), ("partial", [], 0),
    ("order", ["x", "y", "z"], 1), ("order", ["y", "x", "z"], 0),
])
def test_each_question_type(question: str, answer: object, earned: int) -> None:
    quiz = load_quiz("types.yaml", TYPES).quiz
    result = score(quiz, {question: answer})
    test = next(t for t in result.tests if t.name == question)
    assert test.score == earned


def test_tolerance_edge_is_exact() -> None:
    # 0.3 + 0.05 is 0.35000000000000003 in floats; exact arithmetic accepts 0.35.
    quiz = load_quiz("types.yaml", TYPES).quiz
    assert score(quiz, {"num": 0.35}).tests[1].score == 1


def test_key_scores_full_marks_for_every_quiz() -> None:
    for qf in load_all(QUIZ_COURSE):
        key = key_answers(qf.quiz)
        result = score(qf.quiz, key["answers"])
        assert result.score == result.max_score, qf.quiz.id
        assert result.passed


def _write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "answers.json"
    path.write_text(text)
    return path


BAD_ANSWERS = [
    ("not-json", '{"quiz": "rclpy-part2",\n "answers": {', "answers.json:2: not valid JSON"),
    ("wrong-quiz", '{"quiz": "callback-groups", "answers": {}}',
     "answers quiz 'callback-groups', not 'rclpy-part2'"),
    ("unknown-question", '{"quiz": "rclpy-part2",\n "answers": {\n  "nope": "a"}}',
     "answers.json:3: no question 'nope' in quiz 'rclpy-part2'"),
    ("unknown-option", '{"quiz": "rclpy-part2", "answers": {"gil": "gvl"}}',
     "question 'gil' has no option 'gvl'"),
    ("wrong-shape", '["gil"]', "must be a JSON object"),
    ("number-for-choice", '{"quiz": "rclpy-part2", "answers": {"gil": 3}}',
     "question 'gil' needs one option id"),
]


@pytest.mark.parametrize(("text", "message"), [b[1:] for b in BAD_ANSWERS],
                         ids=[b[0] for b in BAD_ANSWERS])
def test_bad_answers_file(tmp_path: Path, text: str, message: str) -> None:
    path = _write(tmp_path, text)
    quiz = load_quiz(PART2).quiz
    with pytest.raises(ContentError) as info:
        read_answers(path, quiz)
    assert message in str(info.value) and str(path.name) in str(info.value)
    results = tmp_path / "results.json"
    cli = CliRunner().invoke(quiz_cli, ["score", "rclpy-part2", str(path),
                                        "--results", str(results)])
    assert cli.exit_code == 2
    assert "Traceback" not in cli.output
    assert len(cli.output.strip().splitlines()) == 1 and message in cli.output
    assert not results.exists()


def test_score_cli_writes_results_in_urdu(tmp_path: Path) -> None:
    answers = {"quiz": "rclpy-part2", "answers": {
        "callback-groups-purpose": "concurrency", "declare-parameters": "declare",
        "gil": "cpython-lock", "shared-resources": "reentrant"}}
    path = _write(tmp_path, json.dumps(answers))
    results = tmp_path / "out" / "results.json"
    cli = CliRunner().invoke(quiz_cli, ["score", "rclpy-part2", str(path), "--lang", "ur",
                                        "--results", str(results)])
    assert cli.exit_code == 0, cli.output
    data = json.loads(results.read_text())
    assert (data["score"], data["max_score"], data["passed"]) == (3, 5, False)
    assert data["quiz"] == "rclpy-part2" and data["lang"] == "ur"
    assert data["pass_summary"] == "کامیابی کے لیے درکار اسکور: 70% (4/5 سوالات)"
    assert [t["status"] for t in data["tests"]] == ["passed"] * 3 + ["failed"] * 2
    assert data["tests"][4]["message"] == "آپ نے جواب نہیں دیا۔"
    assert "ابھی کامیاب نہیں" in cli.output


def test_score_cli_speaks_the_answers_files_language_unless_told(tmp_path: Path) -> None:
    """An answers file saved in Urdu is scored in Urdu; --lang (here or on autograder)
    wins."""
    from autograder.cli import main

    answers = {"quiz": "rclpy-part2", "lang": "ur", "answers": {"gil": "ros-lock"}}
    path = _write(tmp_path, json.dumps(answers))
    results = tmp_path / "results.json"
    urdu = CliRunner().invoke(quiz_cli, ["score", "rclpy-part2", str(path),
                                         "--results", str(results)])
    assert urdu.exit_code == 0, urdu.output
    assert "ابھی کامیاب نہیں" in urdu.stdout and "Not passed yet" not in urdu.stdout
    assert json.loads(results.read_text())["lang"] == "ur"
    english = CliRunner().invoke(quiz_cli, ["score", "rclpy-part2", str(path), "--lang", "en"])
    assert "Not passed yet" in english.stdout
    on_main = CliRunner().invoke(main, ["--lang", "en", "quiz", "score", "rclpy-part2",
                                        str(path)])
    assert on_main.exit_code == 0, on_main.output
    assert "Not passed yet" in on_main.stdout


def test_score_cli_shows_each_question_and_the_answer_given(tmp_path: Path) -> None:
    answers = {"quiz": "rclpy-part2", "answers": {"gil": "ros-lock",
                                                  "declare-parameters": "declare"}}
    path = _write(tmp_path, json.dumps(answers))
    cli = CliRunner().invoke(quiz_cli, ["score", "rclpy-part2", str(path), "--lang", "en"])
    lines = cli.stdout.splitlines()
    assert " ✘ 3. What is the Global Interpreter Lock (GIL)? (0/1)" in lines
    assert ("      Incorrect. Your answer: “A lock that ROS 2 puts on each topic so that two "
            "nodes cannot publish …") in lines
    assert " ✔ 2. How do you declare a parameter in a Python ROS 2 node? (1/1)" in lines
    assert " ✘ 1. What is the main purpose of callback groups in rclpy? (0/1)" in lines
    assert lines[lines.index(" ✘ 1. What is the main purpose of callback groups in rclpy? "
                             "(0/1)") + 1] == "      Not answered."
    assert all(len(line) < 120 for line in lines if line.startswith(" ✘") or
               "Your answer" in line)


@pytest.mark.parametrize(("question", "answer", "text"), [
    ("tf", False, "“False”"), ("tf", "true", "“True”"), ("num", 0.355, "0.355"),
    ("all-or-nothing", ["b", "a"], "“B”, “A”"), ("order", ["z", "x", "y"], "“Z”, “X”, “Y”")])
def test_an_answer_reads_back_as_the_student_chose_it(question, answer, text) -> None:
    from autograder.quiz.localize import Localizer
    from autograder.quiz.types import question_type

    quiz = load_quiz("types.yaml", TYPES).quiz
    q = quiz.question(question)
    assert question_type(q.type).answer_text(quiz, q, answer, Localizer(quiz, "en")) == text


def test_key_cli_prints_a_full_marks_answers_file(tmp_path: Path) -> None:
    key = CliRunner().invoke(quiz_cli, ["key", "error-handling"])
    path = _write(tmp_path, key.output)
    cli = CliRunner().invoke(quiz_cli, ["score", "error-handling", str(path), "--json"])
    data = json.loads(cli.output)
    assert data["score"] == data["max_score"] == 6 and data["passed"]
