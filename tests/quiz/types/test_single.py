"""``single``: one option is right; the key, the answers and the inputs name its id."""

from __future__ import annotations

from fractions import Fraction

import pytest

from autograder.core.errors import ContentError
from autograder.quiz.types import question_type

SINGLE = """
id: pick
type: single
text: Which topic carries velocity commands?
options: [{id: scan, text: /scan}, {id: cmd, text: /cmd_vel}, {id: odom, text: /odom}]
answer: cmd
"""


def test_the_right_option_earns_everything_any_other_nothing(one_question) -> None:
    _quiz, q = one_question(SINGLE)
    kind = question_type("single")
    assert kind.credit(q, "cmd") == Fraction(1)
    assert kind.credit(q, "scan") == kind.credit(q, "odom") == Fraction(0)
    assert kind.key(q) == "cmd"


def test_the_key_must_be_one_of_its_options(one_question) -> None:
    with pytest.raises(ContentError, match=r"t.yaml:\d+: questions\[pick\].answer: the key "
                                           r"must be one option id \(scan, cmd, odom\), "
                                           r"found 'tf'"):
        one_question(SINGLE.replace("answer: cmd", "answer: tf"))
    with pytest.raises(ContentError, match="found \\['cmd'\\]"):
        one_question(SINGLE.replace("answer: cmd", "answer: [cmd]"))


def test_an_answer_names_one_known_option(one_question) -> None:
    _quiz, q = one_question(SINGLE)
    kind = question_type("single")
    assert kind.answer_problem(q, "odom") is None
    assert "has no option 'tf' (options: scan, cmd, odom)" in kind.answer_problem(q, "tf")
    assert "needs one option id, found ['cmd']" in kind.answer_problem(q, ["cmd"])


def test_the_terminal_takes_one_number_of_the_options_shown(one_question, view_of) -> None:
    quiz, _q = one_question(SINGLE)
    view = view_of(quiz, seed=5)
    kind = question_type("single")
    for number, option in enumerate(view.options, 1):
        assert kind.parse_terminal(view, str(number)) == option.id
    for wrong in ("0", "4", "1,2", "x"):
        with pytest.raises(ValueError):
            kind.parse_terminal(view, wrong)
    assert kind.prompt(view) == "Your answer (1 to 3, Enter to skip)"


def test_the_form_gives_the_first_value_or_nothing(one_question) -> None:
    _quiz, q = one_question(SINGLE)
    kind = question_type("single")
    assert kind.parse_form(q, {"q:pick": ["", "odom"]}) == "odom"
    assert kind.parse_form(q, {"q:pick": [""]}) is None and kind.parse_form(q, {}) is None
