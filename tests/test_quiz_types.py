"""The question-type registry is the single source: a type registered there, and nowhere
else, is loaded, rendered, answered (terminal and web form), scored and linted."""

from __future__ import annotations

import json
from collections.abc import Iterator
from fractions import Fraction
from pathlib import Path
from typing import Any

import pytest
from click.testing import CliRunner

from autograder.cli.quiz import quiz_cli
from autograder.core.errors import ContentError
from autograder.i18n.text import markdown_inline
from autograder.quiz.catalog import load_all
from autograder.quiz.model import Question, load_quiz
from autograder.quiz.render import render_markdown, render_page
from autograder.quiz.scoring import check_answers, key_answers, score
from autograder.quiz.server import form_answers
from autograder.quiz.types import question_type, registry
from autograder.quiz.types.base import (
    Form,
    LintNote,
    QuestionType,
    Where,
    check_option_list_key,
    first_value,
    one_option_problem,
    one_picked_id,
)
from autograder.quiz.views import QuestionView, question_views
from content import Document

REPO = Path(__file__).resolve().parent.parent
SHIPPED = {"single", "multiple", "true_false", "numeric", "ordering"}


class AnyOf(QuestionType):
    """A toy type: pick one option; any of the ids the key lists is right."""

    name = "any_of"
    form_template = "quiz_types/single.html"  # radio buttons, as single

    def check_key(self, doc: Document, q: Question, where: Where) -> None:
        if not check_option_list_key(doc, q, where):
            raise doc.error("the key must name at least one option", *where, "answer")

    def lint_notes(self, q: Question, index: int) -> list[LintNote]:
        if len(q.answer) == len(q.options):
            return [LintNote("answer", "every option is right")]
        return []

    def answer_problem(self, q: Question, value: Any) -> str | None:
        return one_option_problem(q, value)

    def credit(self, q: Question, value: Any) -> Fraction:
        return Fraction(value in q.answer)

    def key(self, q: Question) -> Any:
        return q.answer[0]

    def prompt(self, view: QuestionView) -> str:
        return "Any right one"

    def parse_terminal(self, view: QuestionView, raw: str) -> Any:
        return one_picked_id(view, raw)

    def parse_form(self, q: Question, form: Form) -> Any | None:
        return first_value(q, form)

    def markdown_lines(self, view: QuestionView) -> list[str]:
        return [f"- ◇ {markdown_inline(o.text)}" for o in view.options] + [""]


TOY = """\
id: toy
title: Toy
questions:
  - id: colour
    type: any_of
    text: Name a primary colour.
    options: [{id: red, text: Red}, {id: green, text: Green}, {id: blue, text: Blue}]
    answer: [red, blue]
  - id: sure
    type: true_false
    text: Toys are fun.
    answer: true
"""


@pytest.fixture
def any_of(monkeypatch: pytest.MonkeyPatch) -> Iterator[AnyOf]:
    kind = AnyOf()
    monkeypatch.setitem(registry(), kind.name, kind)
    yield kind


def test_shipped_types_are_the_registry() -> None:
    assert set(registry()) == SHIPPED
    assert {q.type for qf in load_all(REPO) for q in qf.quiz.questions} == SHIPPED
    for name, kind in registry().items():
        assert kind.name == name
        assert (REPO / "autograder" / "templates" / kind.form_template).is_file(), name


def test_accepted_type_values_are_the_registry_keys(tmp_path: Path) -> None:
    path = tmp_path / "toy.yaml"
    path.write_text(TOY)
    with pytest.raises(ContentError) as info:
        load_quiz(path)
    allowed = ", ".join(repr(name) for name in sorted(registry()))
    assert str(info.value) == (f"{path}:5: questions[colour].type: must be one of {allowed}, "
                               "found 'any_of'")


def test_registered_type_loads_renders_and_scores(any_of: AnyOf) -> None:
    quiz = load_quiz("toy.yaml", TOY).quiz
    assert quiz.question("colour").option_ids == ("red", "green", "blue")

    page = render_page(quiz, "en", seed=3)
    for colour in ("red", "green", "blue"):
        assert f'<input type="radio" name="q:colour" value="{colour}">' in page
    assert '"any_of": function (section)' in page  # its reader saves the answers file
    markdown = render_markdown(quiz, "en")
    assert "- ◇ Red" in markdown and "- ○ True" in markdown

    assert key_answers(quiz)["answers"] == {"colour": "red", "sure": "true"}
    assert [t.score for t in score(quiz, {"colour": "blue", "sure": True}).tests] == [1, 1]
    assert score(quiz, {"colour": "green"}).tests[0].message == "Incorrect."
    with pytest.raises(ContentError, match="question 'colour' has no option 'pink'"):
        check_answers("a.json", quiz, {"quiz": "toy", "answers": {"colour": "pink"}})

    assert form_answers(quiz, {"q:colour": ["blue"], "q:sure": [""]}) == {"colour": "blue"}


def test_registered_type_is_checked_by_its_own_rules(any_of: AnyOf) -> None:
    with pytest.raises(ContentError,
                       match=r"toy.yaml:8: questions\[colour\].answer: the key names no"):
        load_quiz("toy.yaml", TOY.replace("[red, blue]", "[red, pink]"))
    with pytest.raises(ContentError, match="only a numeric question has a tolerance"):
        load_quiz("toy.yaml", TOY.replace("answer: [red, blue]",
                                          "answer: [red, blue]\n    tolerance: 1"))
    quiz = load_quiz("toy.yaml", TOY.replace("[red, blue]", "[red, green, blue]")).quiz
    assert question_type("any_of").lint_notes(quiz.questions[0], 0) == [
        LintNote("answer", "every option is right")]


def test_registered_type_is_taken_in_the_terminal(any_of: AnyOf, tmp_path: Path) -> None:
    path = tmp_path / "toy.yaml"
    path.write_text(TOY)
    quiz = load_quiz(path).quiz
    view = question_views(quiz, "en", "4")[0]
    blue = 1 + [o.id for o in view.options].index("blue")
    save = tmp_path / "answers.json"
    result = CliRunner().invoke(quiz_cli, ["take", str(path), "--seed", "4", "--save", str(save)],
                                input=f"9\n{blue}\n1\n")
    assert result.exit_code == 0, result.output
    assert "Any right one" in result.output and "That is not an answer" in result.output
    assert "Passed: 2 of 2 (100%)" in result.output
    assert json.loads(save.read_text())["answers"] == {"colour": "blue", "sure": "true"}
