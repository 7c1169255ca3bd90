"""One bad quiz file is one problem: the other quizzes list, serve and score, the broken one
is listed with its error, naming the question by id; `quiz key` prints keys that paste back
into the quiz file and score full marks as an answers file (autograder/quiz/catalog.py)."""

from __future__ import annotations

import json
import re
import urllib.request
from pathlib import Path
from threading import Thread

import pytest
import yaml
from click.testing import CliRunner

from autograder.cli import main
from autograder.cli.quiz import quiz_cli
from autograder.quiz.catalog import find_quiz, load_each
from autograder.quiz.model import load_quiz
from autograder.quiz.scoring import score
from autograder.quiz.server import QuizServer
from content import ContentError

GOOD = """\
id: good
title: A good quiz
languages: [en]
questions:
  - id: pick
    type: single
    text: Pick a
    options: [{id: a, text: A}, {id: b, text: B}]
    answer: a
  - id: judge
    type: true_false
    text: The sky is green.
    answer: false
  - id: many
    type: multiple
    text: Pick both
    options: [{id: a, text: A}, {id: b, text: B}, {id: c, text: C}]
    answer: [a, b]
  - id: count
    type: numeric
    text: How many?
    answer: 8
    tolerance: 0
  - id: order
    type: ordering
    text: In order
    options: [{id: x, text: X}, {id: y, text: Y}]
    answer: [y, x]
"""
# The key of its second question has the wrong shape: a list where one id belongs.
BROKEN = GOOD.replace("id: good", "id: broken").replace("    answer: false\n",
                                                          "    answer: [a]\n")


@pytest.fixture
def course(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    (tmp_path / "assignments").mkdir()
    quizzes = tmp_path / "quizzes"
    quizzes.mkdir()
    (quizzes / "good.yaml").write_text(GOOD)
    (quizzes / "broken.yaml").write_text(BROKEN)
    monkeypatch.setenv("AUTOGRADER_COURSE", str(tmp_path))
    return tmp_path


def test_the_broken_file_names_the_question_by_id(course: Path) -> None:
    files, errors = load_each()
    assert [qf.quiz.id for qf in files] == ["good"]
    assert [str(e) for e in errors] == [
        f"{course / 'quizzes' / 'broken.yaml'}:13: questions[judge].answer: the key must be "
        "true or false, found ['a']"]


def test_list_shows_the_others_and_the_broken_one_with_its_error(course: Path) -> None:
    for command, args in ((main, ["list"]), (quiz_cli, ["list"])):
        result = CliRunner().invoke(command, args)
        assert result.exit_code == 0, result.output
        assert "A good quiz" in result.output
        assert "broken" in result.output and "questions[judge].answer" in result.output
    result = CliRunner().invoke(quiz_cli, ["list", "--json"])
    listed = {e["id"]: e for e in json.loads(result.output)}
    assert "error" not in listed["good"] and "questions[judge]" in listed["broken"]["error"]


def test_the_others_are_found_and_the_broken_one_says_why(course: Path) -> None:
    assert find_quiz("good").quiz.id == "good"
    with pytest.raises(ContentError, match=r"questions\[judge\]\.answer"):
        find_quiz("broken")
    result = CliRunner().invoke(quiz_cli, ["key", "broken"])
    assert result.exit_code == 2 and "questions[judge].answer" in result.output


def test_serve_serves_the_others(course: Path) -> None:
    files, _errors = load_each()
    server = QuizServer(files, 0, "en")
    thread = Thread(target=server.serve_forever, kwargs={"poll_interval": 0.02}, daemon=True)
    thread.start()
    try:
        page = urllib.request.urlopen(server.url + "quiz/good", timeout=10).read().decode()
        assert "Pick a" in page
    finally:
        server.shutdown()
        server.server_close()


def test_the_key_pastes_back_into_the_file_and_scores_full_marks(course: Path,
                                                                 tmp_path: Path) -> None:
    result = CliRunner().invoke(quiz_cli, ["key", "good"])
    assert result.exit_code == 0, result.output
    key = json.loads(result.output)
    assert key["answers"]["judge"] is False  # a boolean, as the file states it
    quiz = find_quiz("good").quiz
    assert score(quiz, key["answers"]).score == quiz.max_score
    data = yaml.safe_load(GOOD)
    for question in data["questions"]:
        question["answer"] = key["answers"][question["id"]]  # pasted back
    pasted = tmp_path / "pasted.yaml"
    pasted.write_text(yaml.safe_dump(data))
    assert load_quiz(pasted).quiz.questions == quiz.questions
    answers = tmp_path / "answers.json"
    answers.write_text(result.output)
    scored = CliRunner().invoke(quiz_cli, ["score", "good", str(answers)])
    assert scored.exit_code == 0 and "Passed: 5 of 5" in scored.output, scored.output


def test_a_broken_exercise_file_is_listed_beside_the_others(course: Path) -> None:
    import shutil

    mini = Path(__file__).parents[1] / "fixtures" / "mini_course"
    shutil.copytree(mini / "assignments" / "shout", course / "assignments" / "shout")
    (course / "assignments" / "typo").mkdir()
    (course / "assignments" / "typo" / "exercise.yaml").write_text("id: typo\ntitle: [\n")
    result = CliRunner().invoke(main, ["list"])
    assert result.exit_code == 0, result.output
    assert "shout" in result.output and "A good quiz" in result.output
    assert re.search(r"typo +not loaded: .*exercise.yaml:3: YAML error", result.output)
    listed = json.loads(CliRunner().invoke(main, ["list", "--json"]).output)
    assert [e["id"] for e in listed["exercises"]] == ["shout", "typo"]
    assert "error" in listed["exercises"][1]


def test_render_and_export_do_the_others_and_name_the_broken_one(course: Path,
                                                                 tmp_path: Path) -> None:
    out = tmp_path / "pages"
    result = CliRunner().invoke(quiz_cli, ["render", "--format", "html", "--out", str(out)])
    assert result.exit_code == 2 and "questions[judge].answer" in result.output
    assert [p.name for p in out.iterdir()] == ["good.en.html"]
    moodle = tmp_path / "all.xml"
    result = CliRunner().invoke(quiz_cli, ["export", "--format", "moodle-xml", "--out",
                                           str(moodle)])
    assert result.exit_code == 2 and "broken.yaml" in result.output
    assert "A good quiz" in moodle.read_text()
