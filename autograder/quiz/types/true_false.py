"""``true_false``: a statement to judge; the key is ``true`` or ``false``.

Asked like a single-choice question whose two options are True and False, so it keeps
that type's prompt, parsing, form and Markdown; answers may be ``"true"``/``"false"``
(option ids, as the form and the terminal give them) or JSON booleans.
"""

from __future__ import annotations

from fractions import Fraction
from typing import TYPE_CHECKING, Any

from autograder.i18n import _
from autograder.i18n.text import Text
from autograder.quiz.localize import Localizer
from autograder.quiz.model import Question, Quiz
from autograder.quiz.types import register
from autograder.quiz.types.base import Where, one_option_problem
from autograder.quiz.types.single import SingleChoice
from autograder.quiz.views import OptionView
from content import Document

if TYPE_CHECKING:
    from autograder.quiz.export.moodle import MoodleWriter
    from autograder.quiz.export.qti import QtiItem, QtiWriter
    from autograder.quiz.export.xml import El

IDS = ("true", "false")


@register
class TrueFalse(SingleChoice):
    name = "true_false"
    has_options = False

    def check_key(self, doc: Document, q: Question, where: Where) -> None:
        if not isinstance(q.answer, bool):
            raise doc.error(_("the key must be true or false, found {value!r}").format(
                value=q.answer), *where, "answer")

    def option_ids(self, q: Question) -> tuple[str, ...]:
        return IDS

    def key(self, q: Question) -> Any:
        return "true" if q.answer else "false"

    def answer_problem(self, q: Question, value: Any) -> str | None:
        return None if isinstance(value, bool) else one_option_problem(q, value)

    def credit(self, q: Question, value: Any) -> Fraction:
        chosen = value if isinstance(value, bool) else value == "true"
        return Fraction(chosen == q.answer)

    def answer_text(self, quiz: Quiz, q: Question, value: Any, loc: Localizer) -> str:
        if isinstance(value, bool):
            value = "true" if value else "false"
        return super().answer_text(quiz, q, value, loc)

    def option_views(self, quiz: Quiz, q: Question, seed: str | int | None,
                     loc: Localizer) -> tuple[OptionView, ...]:
        # Always True then False, never shuffled: the order is part of how it reads.
        return (OptionView("true", Text(_("True"), loc.lang)),
                OptionView("false", Text(_("False"), loc.lang)))

    def moodle_question(self, q: Question, moodle: MoodleWriter) -> El:
        return moodle.truefalse(q, q.answer)

    def qti_item(self, q: Question, qti: QtiWriter) -> QtiItem:
        # Two choices, True then False as the page shows them, never shuffled.
        return qti.choice(q, [self.key(q)], max_choices=1, shuffle=False)
