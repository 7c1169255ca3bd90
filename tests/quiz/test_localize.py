"""A quiz's strings in the student's language, looked up by each string's own context: a
translation where the catalog has one, English marked as a fallback where it has none, a
code-only string as it is; and a check that refuses a language with any string missing,
naming the first one's file and line."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from autograder.core.errors import ContentError
from autograder.i18n import translations
from autograder.i18n.text import Text
from autograder.quiz.localize import Localizer, require_translation
from autograder.quiz.model import QuizFile, load_quiz

GIL = "What is the Global Interpreter Lock (GIL)?"
GIL_UR = "Global Interpreter Lock (GIL) کیا ہے؟"


def _quiz(course: Path) -> QuizFile:
    return load_quiz(course / "quizzes" / "part2-rclpy.yaml")


def _untranslate(course: Path, context: str) -> None:
    po = course / "locales" / "ur" / "LC_MESSAGES" / "content.po"
    entry = rf'(msgctxt "{re.escape(context)}"\nmsgid (?:"[^\n]*"\n)+)msgstr (?:"[^\n]*"\n)+'
    text, n = re.subn(entry, lambda m: f'{m.group(1)}msgstr ""\n', po.read_text())
    assert n == 1, context
    po.write_text(text)
    translations.cache_clear()


def test_each_string_in_the_students_language(course: Path) -> None:
    qf = _quiz(course)
    gil = next(q for q in qf.quiz.questions if q.id == "gil")
    shared = next(q for q in qf.quiz.questions if q.id == "shared-resources")
    ur, en = Localizer(qf.quiz, "ur"), Localizer(qf.quiz, "en")
    assert ur.text(gil, "text") == Text(GIL_UR, "ur")
    assert en.text(gil, "text") == Text(GIL, "en")
    assert en.quiz_text("title") == Text("Part 2 quiz: Python and ROS 2 with rclpy", "en")
    assert ur.quiz_text("title").lang == "ur" and not ur.quiz_text("title").fallback
    options = {o.id: o for o in shared.options}
    # The same English in two questions has a translation of each question's own.
    assert ur.option(shared, options["none"]) == Text("ان میں سے کوئی نہیں", "ur")
    # A code span alone is never translated, and is not a fallback either.
    assert ur.option(shared, options["reentrant"]) == Text("`ReentrantCallbackGroup`", "ur")


def test_a_missing_translation_is_english_marked_as_fallback(course: Path) -> None:
    _untranslate(course, "quiz:rclpy-part2:gil:text")
    qf = _quiz(course)
    gil = next(q for q in qf.quiz.questions if q.id == "gil")
    shown = Localizer(qf.quiz, "ur").text(gil, "text")
    assert shown == Text(GIL, "en", fallback=True)
    assert not shown.rtl  # laid out as English, inside the Urdu page
    assert Localizer(qf.quiz, "ur").quiz_text("title").fallback is False  # only that one


def test_require_translation_names_the_first_missing_string(course: Path) -> None:
    require_translation(_quiz(course), "ur")  # complete: nothing raised
    _untranslate(course, "quiz:rclpy-part2:gil:explanation")
    _untranslate(course, "quiz:rclpy-part2:gil:text")
    qf = _quiz(course)
    require_translation(qf, "en")  # English needs no catalog
    with pytest.raises(ContentError) as raised:
        require_translation(qf, "ur")
    assert raised.value.path == course / "quizzes" / "part2-rclpy.yaml"
    assert raised.value.line == 44  # the question's text, before its explanation
    assert "no ur translation of quiz:rclpy-part2:gil:text" in raised.value.message
