"""``ordering``: put the items (the ``options``) in order; the key lists every id in order.

The file's order is the answer, so items are always scrambled, seed or not, and never
shown in key order; none may be pinned.
"""

from __future__ import annotations

from fractions import Fraction
from typing import TYPE_CHECKING, Any

from autograder.i18n import _
from autograder.i18n.text import markdown_inline
from autograder.quiz.model import Option, Question, Quiz
from autograder.quiz.shuffle import attempt_rng
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
class Ordering(QuestionType):
    name = "ordering"
    form_template = "quiz_types/ordering.html"

    def check_option(self, doc: Document, q: Question, option: Option, at: Where) -> None:
        if option.pin:
            raise doc.error(_("items of an ordering question cannot be pinned"), *at, "pin")

    def check_key(self, doc: Document, q: Question, where: Where) -> None:
        ids = q.option_ids
        if len(check_option_list_key(doc, q, where)) != len(ids):
            raise doc.error(_("the key must put every item in order ({ids})").format(
                ids=", ".join(ids)), *where, "answer")

    def answer_problem(self, q: Question, value: Any) -> str | None:
        return option_list_problem(q, value)  # a partial order is an answer; it scores 0

    def credit(self, q: Question, value: Any) -> Fraction:
        return Fraction(list(value) == list(q.answer))

    def option_order(self, quiz: Quiz, q: Question, seed: str | int | None) -> tuple[Option, ...]:
        options = list(q.options)
        attempt_rng(quiz.id if seed is None else seed, quiz, q).shuffle(options)
        if [o.id for o in options] == list(q.answer) and len(options) > 1:
            options = options[1:] + options[:1]
        return tuple(options)

    def prompt(self, view: QuestionView) -> str:
        return _("The order (numbers separated by spaces, first one first)")

    def parse_terminal(self, view: QuestionView, raw: str) -> Any:
        ids = picked_ids(view, raw)
        if len(ids) != len(view.options):
            raise ValueError(raw)
        return ids

    def parse_form(self, q: Question, form: Form) -> Any | None:
        # One select per item, named q:<question>:<item>, holding the item's place.
        places = []
        for i, o in enumerate(q.options):
            place = form.get(f"q:{q.id}:{o.id}", [""])[0]
            if place.isdigit():
                places.append((int(place), i, o.id))
        if len(places) != len(q.options):
            return None
        return [oid for _place, _i, oid in sorted(places)]

    def form_problem(self, q: Question, form: Form) -> str | None:
        places = [form.get(f"q:{q.id}:{o.id}", [""])[0] for o in q.options]
        given = [p for p in places if p]
        twice = sorted({p for p in given if given.count(p) > 1}, key=lambda p: (len(p), p))
        if twice:
            return _("Two items have the same place, {place}: give each item a place of its "
                     "own.").format(place=twice[0])
        if given and len(given) != len(places):
            return _("Give every item its place (or none, to leave the question out).")
        return None

    def markdown_lines(self, view: QuestionView) -> list[str]:
        return [_("Put these in order:"), "",
                *(f"- [ ] {markdown_inline(o.text)}" for o in view.options), ""]

    def moodle_question(self, q: Question, moodle: MoodleWriter) -> El:
        return moodle.ordering(q, q.answer)

    def qti_item(self, q: Question, qti: QtiWriter) -> QtiItem:
        return qti.order(q, q.answer)
