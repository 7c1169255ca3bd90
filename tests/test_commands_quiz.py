"""The ``quiz`` commands as plain functions (autograder/commands/quiz.py): they talk through
a console and raise the project's errors, with no click in sight."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from autograder.commands.quiz import (
    NotLoaded,
    export_quizzes,
    quiz_list,
    render_quizzes,
    take_quiz,
    use_language,
)
from autograder.core.errors import ContentError, UsageError
from autograder.i18n import get_language, set_language

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
"""


class Script:
    """A console that answers from a list and keeps what it was told."""

    def __init__(self, answers: list[str]) -> None:
        self.answers = answers
        self.out: list[str] = []
        self.err: list[str] = []

    def say(self, text: str, *, err: bool = False) -> None:
        (self.err if err else self.out).append(text)

    def ask(self, prompt: str) -> str:
        return self.answers.pop(0)


@pytest.fixture
def course(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[Path]:
    """A course of one good quiz and two files that do not load."""
    (tmp_path / "assignments").mkdir()
    quizzes = tmp_path / "quizzes"
    quizzes.mkdir()
    (quizzes / "good.yaml").write_text(GOOD)
    (quizzes / "bad-one.yaml").write_text("id: [\n")
    (quizzes / "bad-two.yaml").write_text("id: [\n")
    monkeypatch.setenv("AUTOGRADER_COURSE", str(tmp_path))
    before = get_language()
    yield tmp_path
    set_language(before)


def test_take_asks_again_on_nonsense_and_scores_the_answer(course: Path) -> None:
    console = Script(["9", "nonsense", "1"])
    take_quiz(console, "good", "en", "1", None)
    assert console.answers == []
    assert console.err == ["That is not an answer to this question; try again."] * 2
    assert any("Passed: 1 of 1 (100%)" in line for line in console.out)


def test_render_yields_the_good_files_then_names_every_left_out(course: Path,
                                                                tmp_path: Path) -> None:
    pages = render_quizzes((), None, "html", None, tmp_path / "pages")
    assert next(pages).name == "good.en.html"
    with pytest.raises(NotLoaded) as caught:
        next(pages)
    assert len(caught.value.earlier) == 1 and isinstance(caught.value, UsageError)
    assert "bad-" in str(caught.value) and "bad-" in caught.value.earlier[0]


def test_export_of_an_unknown_quiz_is_a_content_error(course: Path, tmp_path: Path) -> None:
    with pytest.raises(ContentError):
        list(export_quizzes(("no-such-quiz",), "qti", None, tmp_path / "x.zip"))


def test_list_names_the_files_that_did_not_load(course: Path) -> None:
    lines = quiz_list(as_json=False).splitlines()
    assert lines[-1].startswith("good  A good quiz  [en]")
    assert sum("not loaded:" in line for line in lines) == 2


def test_use_language_keeps_the_active_one_when_none_is_given(course: Path) -> None:
    set_language("ur")
    assert use_language(None) == "ur"
