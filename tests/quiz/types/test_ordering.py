"""``ordering``: every item in the key's order; only the whole order earns the points, and
an attempt never shows the items already in order."""

from __future__ import annotations

import pytest

from autograder.core.errors import ContentError
from autograder.quiz.types import question_type

ORDERING = """
id: life
type: ordering
text: Put a node's life in order.
options: [{id: init, text: rclpy.init}, {id: make, text: Node()},
          {id: spin, text: spin}, {id: down, text: shutdown}]
answer: [init, make, spin, down]
"""


def test_only_the_whole_order_earns_the_points(one_question) -> None:
    _quiz, q = one_question(ORDERING)
    kind = question_type("ordering")
    assert kind.credit(q, ["init", "make", "spin", "down"]) == 1
    assert kind.credit(q, ["make", "init", "spin", "down"]) == 0
    assert kind.credit(q, ["init", "make", "spin"]) == 0  # a partial order is an answer
    assert kind.answer_problem(q, ["init", "make", "spin"]) is None


def test_the_key_orders_every_item_and_no_item_is_pinned(one_question) -> None:
    with pytest.raises(ContentError, match=r"the key must put every item in order "
                                           r"\(init, make, spin, down\)"):
        one_question(ORDERING.replace("answer: [init, make, spin, down]",
                                      "answer: [init, make, spin]"))
    with pytest.raises(ContentError, match="items of an ordering question cannot be pinned"):
        one_question(ORDERING.replace("{id: down, text: shutdown}",
                                      "{id: down, text: shutdown, pin: true}"))


def test_no_attempt_shows_the_items_in_the_right_order(one_question, view_of) -> None:
    quiz, q = one_question(ORDERING)
    for seed in (None, *range(40)):
        shown = [o.id for o in view_of(quiz, seed).options]
        assert sorted(shown) == sorted(q.answer) and shown != list(q.answer)


def test_the_terminal_takes_every_item_once(one_question, view_of) -> None:
    quiz, _q = one_question(ORDERING)
    view = view_of(quiz, 1)
    kind = question_type("ordering")
    ids = [o.id for o in view.options]
    assert kind.parse_terminal(view, "4 3 2 1") == ids[::-1]
    for wrong in ("1 2 3", "1 1 2 3", "1 2 3 5"):
        with pytest.raises(ValueError):
            kind.parse_terminal(view, wrong)


def test_the_form_gives_each_item_a_place(one_question) -> None:
    _quiz, q = one_question(ORDERING)
    kind = question_type("ordering")
    places = {"q:life:init": ["2"], "q:life:make": ["1"], "q:life:spin": ["4"],
              "q:life:down": ["3"]}
    assert kind.parse_form(q, places) == ["make", "init", "down", "spin"]
    assert kind.form_problem(q, places) is None
    assert kind.parse_form(q, {**places, "q:life:down": [""]}) is None
    assert kind.form_problem(q, {**places, "q:life:down": [""]}) == (
        "Give every item its place (or none, to leave the question out).")
    assert "Two items have the same place, 1" in kind.form_problem(
        q, {**places, "q:life:init": ["1"]})
    assert kind.form_problem(q, {}) is None  # left out: no problem, not answered
