"""``numeric``: a number within ``tolerance`` of the key, compared exactly, with an
optional unit; a web form may type it with Urdu or Arabic-Indic digits."""

from __future__ import annotations

import pytest

from autograder.core.errors import ContentError
from autograder.quiz.localize import Localizer
from autograder.quiz.types import question_type

NUMERIC = """
id: rate
type: numeric
text: At what rate, in Hz, does a 0.1 s timer fire?
answer: 10
tolerance: 0.5
unit: Hz
"""


def test_within_the_tolerance_is_right_exactly_at_its_edge_too(one_question) -> None:
    _quiz, q = one_question(NUMERIC)
    kind = question_type("numeric")
    assert kind.credit(q, 10) == kind.credit(q, 9.5) == kind.credit(q, 10.5) == 1
    assert kind.credit(q, 10.51) == kind.credit(q, 9.4999) == 0
    _quiz, exact = one_question(NUMERIC.replace("answer: 10", "answer: 0.3")
                                .replace("tolerance: 0.5", "tolerance: 0.05"))
    assert kind.credit(exact, 0.35) == 1  # no float error at the edge


def test_the_key_and_tolerance_are_finite_numbers(one_question) -> None:
    with pytest.raises(ContentError, match="the key must be a number, found 'ten'"):
        one_question(NUMERIC.replace("answer: 10", "answer: ten"))
    with pytest.raises(ContentError, match="the key must be a number, found True"):
        one_question(NUMERIC.replace("answer: 10", "answer: true"))
    with pytest.raises(ContentError, match="the tolerance must be a finite number, 0 or more"):
        one_question(NUMERIC.replace("tolerance: 0.5", "tolerance: -1"))
    with pytest.raises(ContentError, match="a numeric question has no options"):
        one_question(NUMERIC + "options: [{id: a, text: A}, {id: b, text: B}]\n")


def test_lint_notes_a_tolerance_that_also_accepts_zero(one_question) -> None:
    _quiz, q = one_question(NUMERIC.replace("tolerance: 0.5", "tolerance: 10"))
    (note,) = question_type("numeric").lint_notes(q, 0)
    assert note.field == "tolerance" and "also accepts 0" in note.message
    _quiz, fine = one_question(NUMERIC)
    assert question_type("numeric").lint_notes(fine, 0) == []


def test_an_answer_is_a_finite_number_not_a_boolean(one_question) -> None:
    _quiz, q = one_question(NUMERIC)
    kind = question_type("numeric")
    assert kind.answer_problem(q, 9.8) is None and kind.answer_problem(q, 10) is None
    for wrong in ("10", True, float("nan"), float("inf")):
        assert "needs a number" in kind.answer_problem(q, wrong)


def test_the_form_reads_western_urdu_and_arabic_indic_digits(one_question) -> None:
    _quiz, q = one_question(NUMERIC)
    kind = question_type("numeric")
    assert kind.parse_form(q, {"q:rate": [" 9.75 "]}) == 9.75
    assert kind.parse_form(q, {"q:rate": ["۱۰٫۵"]}) == 10.5  # Urdu digits, its separator
    assert kind.parse_form(q, {"q:rate": ["١٠"]}) == 10.0  # Arabic-Indic digits
    assert kind.parse_form(q, {"q:rate": ["ten"]}) is None
    assert "“ten” is not a number" in kind.form_problem(q, {"q:rate": ["ten"]})
    assert kind.form_problem(q, {"q:rate": [""]}) is None
    assert kind.form_problem(q, {"q:rate": ["10"]}) is None


def test_the_answer_reads_back_unrounded_with_its_unit(one_question, view_of) -> None:
    quiz, q = one_question(NUMERIC)
    kind = question_type("numeric")
    assert kind.answer_text(quiz, q, 0.355, Localizer(quiz, "en")) == "0.355 Hz"
    assert kind.parse_terminal(view_of(quiz), "9.5") == 9.5
    with pytest.raises(ValueError):
        kind.parse_terminal(view_of(quiz), "nine")
