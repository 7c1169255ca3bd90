"""``true_false``: the key is a YAML boolean; answers are ``true``/``false`` ids or booleans,
and the two choices always read True, then False."""

from __future__ import annotations

from fractions import Fraction

import pytest

from autograder.core.errors import ContentError
from autograder.quiz.localize import Localizer
from autograder.quiz.types import question_type

TRUE_FALSE = """
id: sure
type: true_false
text: A timer callback runs on the executor's thread.
answer: true
"""


def test_either_form_of_the_right_answer_earns_it(one_question) -> None:
    _quiz, q = one_question(TRUE_FALSE)
    kind = question_type("true_false")
    assert kind.credit(q, True) == kind.credit(q, "true") == Fraction(1)
    assert kind.credit(q, False) == kind.credit(q, "false") == Fraction(0)
    assert kind.key(q) == "true"


def test_the_key_is_a_boolean_and_there_are_no_options(one_question) -> None:
    with pytest.raises(ContentError, match="the key must be true or false, found 'yes please'"):
        one_question(TRUE_FALSE.replace("answer: true", "answer: yes please"))
    with pytest.raises(ContentError, match="a true_false question has no options"):
        one_question(TRUE_FALSE + "options: [{id: a, text: A}, {id: b, text: B}]\n")


def test_an_answer_is_a_boolean_or_one_of_the_two_ids(one_question) -> None:
    _quiz, q = one_question(TRUE_FALSE)
    kind = question_type("true_false")
    assert kind.answer_problem(q, False) is None and kind.answer_problem(q, "false") is None
    assert "has no option 'maybe' (options: true, false)" in kind.answer_problem(q, "maybe")


def test_true_comes_first_whatever_the_seed_and_reads_back_as_its_text(
        one_question, view_of) -> None:
    quiz, q = one_question(TRUE_FALSE)
    for seed in (None, 1, 2, "abc"):
        assert [o.id for o in view_of(quiz, seed).options] == ["true", "false"]
    kind = question_type("true_false")
    view = view_of(quiz, 3)
    assert kind.parse_terminal(view, "2") == "false"
    assert kind.answer_text(quiz, q, False, Localizer(quiz, "en")) == "“False”"
