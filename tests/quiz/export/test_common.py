"""What both exports share (autograder.quiz.export.common): each string in the languages
that translate it, platform messages likewise, and errors that name the question."""

from __future__ import annotations

import pytest

from autograder.core.errors import ContentError
from autograder.i18n import _
from autograder.quiz.export.common import Languages, paragraphs
from autograder.quiz.model import QuizFile, load_quiz

ENGLISH_ONLY = """\
id: toy
title: Toy
languages: [en]
questions:
  - id: first
    type: true_false
    text: One.
    answer: true
  - id: pick
    type: single
    text: Pick.
    options: [{id: a, text: A}, {id: b, text: B}]
    answer: a
"""


@pytest.fixture
def toy(tmp_path) -> QuizFile:
    path = tmp_path / "toy.yaml"
    path.write_text(ENGLISH_ONLY)
    return load_quiz(path)


def test_a_string_no_language_translates_falls_back_to_the_first(toy: QuizFile) -> None:
    languages = Languages(toy, ["en", "ur"])
    texts = languages.texts(lambda loc: loc.text(toy.quiz.questions[0], "text"))
    assert [(t.value, t.lang) for t in texts] == [("One.", "en")]  # no Urdu marked as such


def test_a_platform_message_comes_in_each_language_that_translates_it(toy: QuizFile) -> None:
    both = Languages(toy, ["en", "ur"]).messages(lambda: _("Correct."))
    assert [t.lang for t in both] == ["en", "ur"]
    assert both[0].value == "Correct." and both[1].value != "Correct."
    untranslated = Languages(toy, ["en", "ur"]).messages(lambda: _("no catalog has this"))
    assert [(t.value, t.lang) for t in untranslated] == [("no catalog has this", "en")]


def test_an_error_names_the_questions_file_and_line(toy: QuizFile) -> None:
    error = Languages(toy, ["en"]).unsupported(toy.quiz.questions[1], "qti")
    assert isinstance(error, ContentError)
    assert str(error) == (f"{toy.path}:9: questions[pick]: a single question cannot be "
                          "exported to qti")


def test_paragraphs_split_at_blank_lines_each_on_one_line() -> None:
    assert paragraphs("  One\nline.\n\n\n  Two   words.\n \n") == ["One line.", "Two words."]
    assert paragraphs("") == []
