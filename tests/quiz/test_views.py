"""A question as a student sees it: numbered in the quiz's order, in the student's language,
its options in this attempt's order (the same seed, the same order), and never the key."""

from __future__ import annotations

import dataclasses
from pathlib import Path

from autograder.i18n.text import Text
from autograder.quiz.model import load_quiz
from autograder.quiz.types import question_type
from autograder.quiz.views import OptionView, QuestionView, question_views

QUIZ = """\
id: views
title: Views
questions:
  - id: rate
    type: numeric
    text: At what rate does the timer fire?
    code: |
      node.create_timer(0.1, tick)

    answer: 10
    unit: Hz
    points: 2
    explanation: Once every 0.1 s.
  - id: colour
    type: single
    text: Which colour?
    options:
      - {id: red, text: Red}
      - {id: green, text: Green}
      - {id: blue, text: Blue}
      - {id: amber, text: Amber}
      - {id: none, text: None of these, pin: true}
    answer: blue
  - id: sure
    type: true_false
    text: Are you sure?
    answer: false
"""


def _quiz(tmp_path: Path):
    path = tmp_path / "views.yaml"
    path.write_text(QUIZ)
    return load_quiz(path).quiz


def test_each_question_numbered_with_its_text_code_unit_and_points(tmp_path):
    quiz = _quiz(tmp_path)
    rate, colour, sure = question_views(quiz, "en", "seed")
    assert (rate.number, rate.id, rate.type, rate.points) == (1, "rate", "numeric", 2)
    assert rate.text == Text("At what rate does the timer fire?", "en")
    assert rate.code == "node.create_timer(0.1, tick)"  # trailing blank lines dropped
    assert rate.unit == Text("Hz", "en") and rate.options == ()
    assert (colour.number, colour.unit, colour.code) == (2, None, "")
    assert (sure.number, sure.points) == (3, 1)
    for view in (rate, colour, sure):
        assert view.form_template == question_type(view.type).form_template


def test_options_in_this_attempts_order(tmp_path):
    quiz = _quiz(tmp_path)
    orders = {seed: [o.id for o in question_views(quiz, "en", seed)[1].options]
              for seed in map(str, range(12))}
    assert all(sorted(order) == sorted(["red", "green", "blue", "amber", "none"])
               for order in orders.values())
    assert orders["3"] == [o.id for o in question_views(quiz, "en", "3")[1].options]
    assert len({tuple(order) for order in orders.values()}) > 1  # seeds differ
    assert all(order[-1] == "none" for order in orders.values())  # a pinned option stays
    colour = question_views(quiz, "en", "3")[1]
    assert OptionView("blue", Text("Blue", "en")) in colour.options
    sure = question_views(quiz, "en", "3")[2]
    assert {o.id for o in sure.options} == {"true", "false"}


def test_a_view_holds_no_key(tmp_path):
    quiz = _quiz(tmp_path)
    fields = {f.name for f in dataclasses.fields(QuestionView)}
    assert not fields & {"answer", "key", "tolerance", "explanation", "partial_credit"}
    for view in question_views(quiz, "en", None):
        shown = repr(view)
        assert "Once every 0.1 s." not in shown
        assert "10" not in shown.replace(view.code, "")  # the numeric key, nowhere
