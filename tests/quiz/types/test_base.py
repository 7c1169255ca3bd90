"""What every question type inherits (autograder.quiz.types.base): the options' rules, the
verdict's wording, an attempt's option order, and the parsers the shipped types share."""

from __future__ import annotations

from fractions import Fraction

import pytest

from autograder.core.errors import ContentError
from autograder.quiz.localize import Localizer
from autograder.quiz.types import question_type
from autograder.quiz.types.base import first_value, picked_ids

THREE = """
id: pick
type: single
text: Which?
points: 2
options: [{id: a, text: "Alpha, first"}, {id: b, text: Beta}, {id: c, text: Gamma, pin: true}]
answer: a
"""


def test_options_are_two_or_more_each_with_a_unique_id_and_a_text(one_question) -> None:
    cases = {
        "options: [{id: a, text: A}]": "needs at least 2 options, found 1",
        "options: [{id: a, text: A}, {id: a, text: B}]": "duplicate option id 'a'",
        "options: [{id: a, text: A}, {id: b, text: ' '}]":
            r"options\[b\].text: required field is missing",
        "options: [{id: a, text: A}, {id: B!, text: B}]": "id 'B!' must be lower-case",
    }
    for options, message in cases.items():
        with pytest.raises(ContentError, match=message):
            one_question(THREE.replace(THREE.splitlines()[5], options))


def test_the_verdict_says_how_much_an_answer_earned(one_question) -> None:
    _quiz, q = one_question(THREE)
    kind = question_type("single")
    assert kind.feedback(q, None, Fraction(0), "en") == "Not answered."
    assert kind.feedback(q, "a", Fraction(2), "en") == "Correct."
    assert kind.feedback(q, "b", Fraction(0), "en") == "Incorrect."
    assert kind.feedback(q, "b", Fraction(1, 2), "en") == "Partly correct: 0.5 of 2 points."


def test_an_answer_reads_back_as_its_options_quoted(one_question) -> None:
    quiz, q = one_question(THREE)
    loc = Localizer(quiz, "en")
    assert question_type("single").answer_text(quiz, q, "a", loc) == "“Alpha, first”"
    assert question_type("multiple").answer_text(quiz, q, ["b", "a"], loc) == \
        "“Beta”, “Alpha, first”"


def test_an_attempt_shuffles_the_same_way_for_a_seed_and_keeps_pins(one_question) -> None:
    quiz, q = one_question(THREE)
    kind = question_type("single")
    assert [o.id for o in kind.option_order(quiz, q, None)] == ["a", "b", "c"]
    orders = {tuple(o.id for o in kind.option_order(quiz, q, seed)) for seed in range(30)}
    assert orders == {("a", "b", "c"), ("b", "a", "c")}  # c is pinned to its place
    assert kind.option_order(quiz, q, 11) == kind.option_order(quiz, q, 11)


def test_picked_numbers_become_ids_each_once(one_question, view_of) -> None:
    quiz, q = one_question(THREE)
    view = view_of(quiz)
    assert picked_ids(view, "3,1") == ["c", "a"] and picked_ids(view, " 2 ") == ["b"]
    for wrong in ("", "0", "4", "1 1", "a"):
        with pytest.raises(ValueError):
            picked_ids(view, wrong)
    assert first_value(q, {"q:pick": ["", "b", "c"]}) == "b"
    assert first_value(q, {"q:other": ["b"]}) is None
