"""One question of a type, loaded from the text of a quiz file as a course writes it."""

from __future__ import annotations

import textwrap
from collections.abc import Callable

import pytest

from autograder.i18n import set_language
from autograder.quiz.model import Question, Quiz, load_quiz
from autograder.quiz.views import QuestionView, question_views

Loader = Callable[[str], tuple[Quiz, Question]]


@pytest.fixture(autouse=True)
def english() -> None:
    set_language("en")


@pytest.fixture
def one_question() -> Loader:
    """The quiz and its only question, from that question's YAML (as under ``questions:``,
    without the list's dash)."""
    def load(question: str) -> tuple[Quiz, Question]:
        body = textwrap.indent(textwrap.dedent(question).strip(), "    ")
        text = f"id: t\ntitle: T\nquestions:\n  -{body[3:]}\n"
        quiz = load_quiz("t.yaml", text).quiz
        return quiz, quiz.questions[0]
    return load


@pytest.fixture
def view_of() -> Callable[..., QuestionView]:
    """The first question of a quiz as an attempt with a seed shows it (its options in
    that attempt's order; no seed: the file's)."""
    def view(quiz: Quiz, seed: str | int | None = None) -> QuestionView:
        return question_views(quiz, "en", seed)[0]
    return view
