"""``numeric``: a number, right within ``tolerance`` of the key, with an optional ``unit``.

Compared exactly (as fractions), so 0.3 with a tolerance of 0.05 accepts 0.35.
"""

from __future__ import annotations

import math
from decimal import Decimal
from fractions import Fraction
from typing import TYPE_CHECKING, Any

from babel.numbers import format_decimal

from autograder.core.results import exact
from autograder.i18n import N_, _
from autograder.i18n.text import babel_locale, markdown_inline, terminal
from autograder.quiz.localize import Localizer
from autograder.quiz.model import Question, Quiz
from autograder.quiz.types import register
from autograder.quiz.types.base import Form, LintNote, QuestionType, Where, first_value
from autograder.quiz.views import QuestionView
from content import Document

if TYPE_CHECKING:
    from autograder.quiz.export.moodle import MoodleWriter
    from autograder.quiz.export.qti import QtiItem, QtiWriter
    from autograder.quiz.export.xml import El

# Urdu and Arabic-Indic digits and decimal separator, as a phone keyboard types them.
_DIGITS = str.maketrans("۰۱۲۳۴۵۶۷۸۹٠١٢٣٤٥٦٧٨٩٫", "01234567890123456789.")


def _is_number(value: Any) -> bool:
    return not isinstance(value, bool) and isinstance(value, (int, float)) \
        and math.isfinite(value)


@register
class Numeric(QuestionType):
    name = "numeric"
    form_template = "quiz_types/numeric.html"
    has_options = False
    owned_fields = {"tolerance": N_("only a numeric question has a tolerance")}

    def check_key(self, doc: Document, q: Question, where: Where) -> None:
        if not _is_number(q.answer):
            raise doc.error(_("the key must be a number, found {value!r}").format(
                value=q.answer), *where, "answer")
        if not math.isfinite(q.tolerance) or q.tolerance < 0:
            raise doc.error(_("the tolerance must be a finite number, 0 or more, "
                              "found {value!r}").format(value=q.tolerance), *where, "tolerance")

    def lint_notes(self, q: Question, index: int) -> list[LintNote]:
        if q.answer and q.tolerance >= abs(q.answer):
            return [LintNote("tolerance", _(
                "questions[{id}].tolerance: a tolerance of {tolerance} around {answer} "
                "also accepts 0").format(id=q.id, tolerance=q.tolerance, answer=q.answer))]
        return []

    def answer_problem(self, q: Question, value: Any) -> str | None:
        if _is_number(value):
            return None
        return _("question {id!r} needs a number, found {value!r}").format(id=q.id, value=value)

    def credit(self, q: Question, value: Any) -> Fraction:
        return Fraction(abs(exact(value) - exact(q.answer)) <= exact(q.tolerance))

    def answer_text(self, quiz: Quiz, q: Question, value: Any, loc: Localizer) -> str:
        # The number as given (never rounded: 0.355 is not 0.36), then the unit.
        number = format_decimal(Decimal(repr(value)), locale=babel_locale(loc.lang),
                                decimal_quantization=False)
        return f"{number} {terminal(loc.text(q, 'unit'))}" if q.unit else number

    def prompt(self, view: QuestionView) -> str:
        return _("Your answer (a number, Enter to skip)")

    def parse_terminal(self, view: QuestionView, raw: str) -> Any:
        return float(raw)

    def parse_form(self, q: Question, form: Form) -> Any | None:
        value = first_value(q, form)
        try:
            return float(value.strip().translate(_DIGITS)) if value else None
        except ValueError:
            return None  # not a number: scored as not answered, as a blank box is

    def form_problem(self, q: Question, form: Form) -> str | None:
        value = (first_value(q, form) or "").strip()
        if value and self.parse_form(q, form) is None:
            return _("“{value}” is not a number: write it in digits, such as 8 or 0.25.").format(
                value=value)
        return None

    def markdown_lines(self, view: QuestionView) -> list[str]:
        unit = f" {markdown_inline(view.unit)}" if view.unit else ""
        return [f"{_('Answer:')} \\_\\_\\_\\_\\_\\_{unit}", ""]

    def moodle_question(self, q: Question, moodle: MoodleWriter) -> El:
        return moodle.numerical(q, q.answer, q.tolerance, q.unit)

    def qti_item(self, q: Question, qti: QtiWriter) -> QtiItem:
        return qti.numeric(q, q.answer, q.tolerance, q.unit)
