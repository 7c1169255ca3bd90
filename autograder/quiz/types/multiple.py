"""``multiple``: choose all that apply; the key lists the right option ids.

All or nothing, unless ``partial_credit: true``: then (right picked - wrong picked) /
right, at least 0.
"""

from __future__ import annotations

from fractions import Fraction
from typing import TYPE_CHECKING, Any

from autograder.i18n import N_, _
from autograder.i18n.text import markdown_inline
from autograder.quiz.model import Question
from autograder.quiz.types import register
from autograder.quiz.types.base import (
    Form,
    QuestionType,
    Where,
    check_option_list_key,
    option_list_problem,
    picked_ids,
)
from autograder.quiz.views import QuestionView
from content import Document

if TYPE_CHECKING:
    from autograder.quiz.export.moodle import MoodleWriter
    from autograder.quiz.export.qti import QtiItem, QtiWriter
    from autograder.quiz.export.xml import El


@register
class MultipleChoice(QuestionType):
    name = "multiple"
    form_template = "quiz_types/multiple.html"
    owned_fields = {"partial_credit": N_("only a multiple question gives partial credit")}

    def check_key(self, doc: Document, q: Question, where: Where) -> None:
        if not check_option_list_key(doc, q, where):
            raise doc.error(_("the key must name at least one option"), *where, "answer")

    def answer_problem(self, q: Question, value: Any) -> str | None:
        return option_list_problem(q, value)

    def credit(self, q: Question, value: Any) -> Fraction:
        right, chosen = set(q.answer), set(value)
        if not q.partial_credit:
            return Fraction(chosen == right)
        earned = len(chosen & right) - len(chosen - right)
        return max(Fraction(0), Fraction(earned, len(right)))

    def terminal_lines(self, view: QuestionView) -> list[str]:
        return [_("Choose all that apply."), *super().terminal_lines(view)]

    def prompt(self, view: QuestionView) -> str:
        return _("Your answers (numbers separated by commas, Enter to skip)")

    def parse_terminal(self, view: QuestionView, raw: str) -> Any:
        return picked_ids(view, raw)

    def parse_form(self, q: Question, form: Form) -> Any | None:
        return [v for v in form.get(f"q:{q.id}", []) if v] or None

    def markdown_lines(self, view: QuestionView) -> list[str]:
        return [_("Choose all that apply."), "",
                *(f"- ☐ {markdown_inline(o.text)}" for o in view.options), ""]

    def _shares(self, q: Question, wrong: Fraction) -> dict[str, Fraction]:
        right, share = set(q.answer), Fraction(1, len(q.answer))
        return {o.id: share if o.id in right else wrong for o in q.options}

    def moodle_question(self, q: Question, moodle: MoodleWriter) -> El:
        # Moodle adds up the picks' fractions and keeps the sum within 0..1: with partial
        # credit, a right pick's share less a wrong pick's is the platform's rule.  It has
        # no all-or-nothing multichoice, so then a wrong pick costs everything (-100%):
        # only some right picks and no wrong one earn a share there, 0 here; said in notes.
        if q.partial_credit:
            return moodle.multichoice(q, self._shares(q, -Fraction(1, len(q.answer))),
                                      single=False)
        number = moodle.quiz.questions.index(q) + 1
        moodle.note(lambda: _(
            "Question {number} ({id}) is all or nothing here; in Moodle, some of the right "
            "options picked with no wrong one earn that share of its marks.").format(
                number=number, id=q.id))
        return moodle.multichoice(q, self._shares(q, Fraction(-1)), single=False)

    def qti_item(self, q: Question, qti: QtiWriter) -> QtiItem:
        if q.partial_credit:  # map_response, kept within 0..1 as the platform floors at 0
            return qti.choice(q, q.answer, max_choices=0,
                              mapping=self._shares(q, -Fraction(1, len(q.answer))))
        return qti.choice(q, q.answer, max_choices=0)  # match_correct: the exact set
