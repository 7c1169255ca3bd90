"""``single``: pick one option; the key is its id."""

from __future__ import annotations

from fractions import Fraction
from typing import TYPE_CHECKING, Any

from autograder.i18n import _
from autograder.i18n.text import markdown_inline
from autograder.quiz.model import Question
from autograder.quiz.types import register
from autograder.quiz.types.base import (
    Form,
    QuestionType,
    Where,
    first_value,
    one_option_problem,
    one_picked_id,
)
from autograder.quiz.views import QuestionView
from content import Document

if TYPE_CHECKING:
    from autograder.quiz.export.moodle import MoodleWriter
    from autograder.quiz.export.qti import QtiItem, QtiWriter
    from autograder.quiz.export.xml import El


@register
class SingleChoice(QuestionType):
    name = "single"
    form_template = "quiz_types/single.html"

    def check_key(self, doc: Document, q: Question, where: Where) -> None:
        ids = q.option_ids
        if not isinstance(q.answer, str) or q.answer not in ids:
            raise doc.error(_("the key must be one option id ({ids}), found {value!r}").format(
                ids=", ".join(ids), value=q.answer), *where, "answer")

    def answer_problem(self, q: Question, value: Any) -> str | None:
        return one_option_problem(q, value)

    def credit(self, q: Question, value: Any) -> Fraction:
        return Fraction(value == q.answer)

    def prompt(self, view: QuestionView) -> str:
        return _("Your answer (1 to {count}, Enter to skip)").format(count=len(view.options))

    def parse_terminal(self, view: QuestionView, raw: str) -> Any:
        return one_picked_id(view, raw)

    def parse_form(self, q: Question, form: Form) -> Any | None:
        return first_value(q, form)

    def markdown_lines(self, view: QuestionView) -> list[str]:
        return [f"- ○ {markdown_inline(o.text)}" for o in view.options] + [""]

    def moodle_question(self, q: Question, moodle: MoodleWriter) -> El:
        return moodle.multichoice(q, {o.id: Fraction(o.id == q.answer) for o in q.options},
                                  single=True)

    def qti_item(self, q: Question, qti: QtiWriter) -> QtiItem:
        return qti.choice(q, [q.answer], max_choices=1)
