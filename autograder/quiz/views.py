"""A question as a student sees it: no key, options in this attempt's order.

Every renderer (the HTML page, the Markdown export, the terminal) works from these views,
so none can leak the key; each question's type decides its options.
"""

from __future__ import annotations

import dataclasses

from autograder.i18n.text import Text
from autograder.quiz.localize import Localizer
from autograder.quiz.model import Quiz
from autograder.quiz.types import question_type


@dataclasses.dataclass(frozen=True)
class OptionView:
    id: str
    text: Text


@dataclasses.dataclass(frozen=True)
class QuestionView:
    """One question of one attempt, in the student's language."""

    number: int
    id: str
    type: str
    text: Text
    code: str
    unit: Text | None
    points: int
    options: tuple[OptionView, ...]
    form_template: str


def question_views(quiz: Quiz, lang: str, seed: str | int | None) -> list[QuestionView]:
    loc = Localizer(quiz, lang)
    views = []
    for n, q in enumerate(quiz.questions, 1):
        kind = question_type(q.type)
        views.append(QuestionView(n, q.id, q.type, loc.text(q, "text"), q.code.rstrip(),
                                  loc.text(q, "unit") if q.unit else None, q.points,
                                  kind.option_views(quiz, q, seed, loc), kind.form_template))
    return views
