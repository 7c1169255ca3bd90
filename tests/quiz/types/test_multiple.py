"""``multiple``: a set of right options; all or nothing, or with ``partial_credit`` a share
per right pick less a share per wrong one, never below 0."""

from __future__ import annotations

from fractions import Fraction

import pytest

from autograder.core.errors import ContentError
from autograder.quiz.types import question_type

MULTIPLE = """
id: qos
type: multiple
text: Which are QoS policies?
options: [{id: rel, text: Reliability}, {id: dur, text: Durability},
          {id: hz, text: Frequency}, {id: dep, text: Depth}]
answer: [rel, dur, dep]
"""


def test_all_or_nothing_by_default(one_question) -> None:
    _quiz, q = one_question(MULTIPLE)
    kind = question_type("multiple")
    assert kind.credit(q, ["dep", "rel", "dur"]) == 1  # in any order
    assert kind.credit(q, ["rel", "dur"]) == 0
    assert kind.credit(q, ["rel", "dur", "dep", "hz"]) == 0


def test_partial_credit_is_a_share_per_right_pick_less_one_per_wrong(one_question) -> None:
    _quiz, q = one_question(MULTIPLE + "partial_credit: true\n")
    kind = question_type("multiple")
    assert kind.credit(q, ["rel", "dur"]) == Fraction(2, 3)
    assert kind.credit(q, ["rel", "dur", "hz"]) == Fraction(1, 3)
    assert kind.credit(q, ["hz"]) == 0 and kind.credit(q, ["rel", "hz"]) == 0  # never < 0
    assert kind.credit(q, ["rel", "dur", "dep"]) == 1


def test_the_key_lists_known_options_once_and_at_least_one(one_question) -> None:
    for key, message in (("[rel, tf]", "the key names no option 'tf'"),
                         ("[rel, rel]", "the key names an option twice"),
                         ("[]", "the key must name at least one option"),
                         ("rel", "the key must be a list of option ids, found 'rel'")):
        with pytest.raises(ContentError, match=message):
            one_question(MULTIPLE.replace("answer: [rel, dur, dep]", f"answer: {key}"))


def test_partial_credit_belongs_to_multiple_alone(one_question) -> None:
    with pytest.raises(ContentError, match="only a multiple question gives partial credit"):
        one_question("""
id: one
type: single
text: One?
options: [{id: a, text: A}, {id: b, text: B}]
answer: a
partial_credit: true
""")


def test_an_answer_is_a_list_of_known_options_each_once(one_question) -> None:
    _quiz, q = one_question(MULTIPLE)
    kind = question_type("multiple")
    assert kind.answer_problem(q, ["rel"]) is None and kind.answer_problem(q, []) is None
    assert "needs a list of option ids, found 'rel'" in kind.answer_problem(q, "rel")
    assert "names an option twice" in kind.answer_problem(q, ["rel", "rel"])
    assert "has no option 'x'" in kind.answer_problem(q, ["x"])


def test_the_terminal_and_the_form_take_several(one_question, view_of) -> None:
    quiz, q = one_question(MULTIPLE)
    kind = question_type("multiple")
    view = view_of(quiz, 7)
    ids = [o.id for o in view.options]
    assert kind.parse_terminal(view, "3, 1") == [ids[2], ids[0]]
    assert kind.parse_terminal(view, "2 4") == [ids[1], ids[3]]
    for wrong in ("1,1", "5", ""):
        with pytest.raises(ValueError):
            kind.parse_terminal(view, wrong)
    assert kind.parse_form(q, {"q:qos": ["rel", "", "dep"]}) == ["rel", "dep"]
    assert kind.parse_form(q, {"q:qos": [""]}) is None
    assert kind.terminal_lines(view)[0] == "Choose all that apply."
