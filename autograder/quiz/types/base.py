"""What every question type provides, and the checks and parsers the shipped types share.

A type is the only place that knows what its key, its answers and its inputs look like:
the generic quiz modules call these methods, so a new type is one module in this package
(plus a template snippet under ``autograder/templates/quiz_types/`` if it has its own form).
"""

from __future__ import annotations

import abc
import dataclasses
from collections.abc import Mapping
from fractions import Fraction
from typing import TYPE_CHECKING, Any, ClassVar

from autograder.i18n import _, ngettext, pgettext
from autograder.i18n.text import format_number, terminal
from autograder.quiz.localize import Localizer
from autograder.quiz.model import Option, Question, Quiz, check_id
from autograder.quiz.shuffle import attempt_rng, shuffle_unpinned
from autograder.quiz.views import OptionView, QuestionView
from content import Document

if TYPE_CHECKING:  # the exports build on the types: imported only for annotations
    from autograder.quiz.export.moodle import MoodleWriter
    from autograder.quiz.export.qti import QtiItem, QtiWriter
    from autograder.quiz.export.xml import El

Where = tuple[str | int, ...]
"""Path of a question in its quiz file, ``("questions", index)``, for ``doc.error``."""

Form = Mapping[str, list[str]]
"""A submitted form as ``urllib.parse.parse_qs`` gives it: every name has a list of values."""


@dataclasses.dataclass(frozen=True)
class LintNote:
    """A doubtful but valid setting lint reports: the field it is in, and why."""

    field: str
    message: str


class QuestionType(abc.ABC):
    """One kind of question: its key, its scoring and how it is asked and answered.

    Subclasses set ``name`` and ``form_template`` and implement the abstract methods; the
    others have defaults that suit questions whose options are listed in the file.
    """

    name: ClassVar[str]
    """The ``type:`` a quiz file gives."""

    form_template: ClassVar[str]
    """A Jinja template with two macros: ``form(q)``, the inputs of a ``QuestionView``
    named ``q:<question id>...``, and ``reader()``, a JavaScript function of the question's
    ``<section>`` returning its answer in the answers-file shape (``undefined``: none)."""

    has_options: ClassVar[bool] = True
    """Whether the file lists ``options``; a type without them must have none."""

    owned_fields: ClassVar[Mapping[str, str]] = {}
    """Question fields only this type may set, each with the message (marked with ``N_``)
    a question of another type that sets it gets."""

    # The quiz file ----------------------------------------------------------------------

    def check_options(self, doc: Document, q: Question, where: Where) -> None:
        """Options are present (at least 2) or absent as the type needs; ids valid, unique."""
        if not self.has_options:
            if q.options:
                raise doc.error(_("a {type} question has no options").format(type=q.type),
                                *where, "options")
            return
        if len(q.options) < 2:
            raise doc.error(_("needs at least 2 options, found {count}").format(
                count=len(q.options)), *where, "options")
        ids: set[str] = set()
        for j, o in enumerate(q.options):
            at = (*where, "options", j)
            if not o.id:
                raise doc.error(_("required field is missing"), *at, "id")
            check_id(doc, o.id, *at, "id")
            if o.id in ids:
                raise doc.error(_("duplicate option id {id!r}").format(id=o.id), *at, "id")
            ids.add(o.id)
            if not o.text.strip():
                raise doc.error(_("required field is missing"), *at, "text")
            self.check_option(doc, q, o, at)

    def check_option(  # noqa: B027 - a hook: most types have no rule of their own
            self, doc: Document, q: Question, option: Option, at: Where) -> None:
        """A rule of this type for each option (``at`` is the option's path)."""

    @abc.abstractmethod
    def check_key(self, doc: Document, q: Question, where: Where) -> None:
        """Raise ``doc.error(..., *where, "answer")`` unless ``q.answer`` (never None
        here) is a valid key; check the type's own fields too."""

    def option_ids(self, q: Question) -> tuple[str, ...]:
        """The ids an answer may name."""
        return tuple(o.id for o in q.options)

    def key(self, q: Question) -> Any:
        """The key as an answers file states it (JSON: lists, never tuples)."""
        return list(q.answer) if isinstance(q.answer, (list, tuple)) else q.answer

    def lint_notes(self, q: Question, index: int) -> list[LintNote]:
        """Valid settings that are probably mistakes (``index``: the question's place)."""
        return []

    # One answer -------------------------------------------------------------------------

    @abc.abstractmethod
    def answer_problem(self, q: Question, value: Any) -> str | None:
        """Why ``value`` (from an answers file, never None) cannot be scored, or None."""

    @abc.abstractmethod
    def credit(self, q: Question, value: Any) -> Fraction:
        """The fraction of the points a checked answer earns, from 0 to 1, exactly."""

    def feedback(self, q: Question, value: Any, earned: Fraction, lang: str) -> str:
        """The one-line verdict on an answer (None: left out) that earned ``earned`` of the
        question's points, in the active language (numbers formatted for ``lang``)."""
        points = Fraction(q.points)
        if value is None:
            return _("Not answered.")
        if earned == points:
            return _("Correct.")
        if earned:
            return ngettext("Partly correct: {score} of {max} point.",
                            "Partly correct: {score} of {max} points.", q.points).format(
                score=format_number(earned, lang), max=format_number(points, lang))
        return _("Incorrect.")

    def answer_text(self, quiz: Quiz, q: Question, value: Any, loc: Localizer) -> str:
        """A checked answer (never None) as the student reads it back in a terminal: the
        texts of the options it names, in its order."""
        texts = {v.id: terminal(v.text) for v in self.option_views(quiz, q, None, loc)}
        chosen = value if isinstance(value, list) else [value]
        # Each option in quotes: an option may hold commas of its own, and a true/false
        # option read bare beside the feedback ("Correct. Your answer: False") contradicts it.
        return pgettext("between the options a student chose", ", ").join(
            _("“{option}”").format(option=texts.get(str(c), str(c))) for c in chosen)

    # One attempt ------------------------------------------------------------------------

    def option_order(self, quiz: Quiz, q: Question, seed: str | int | None) -> tuple[Option, ...]:
        """Options in the order this attempt shows them: the file's order without a seed,
        else shuffled with pinned options kept in place."""
        if seed is None:
            return q.options
        return shuffle_unpinned(q.options, attempt_rng(seed, quiz, q))

    def option_views(self, quiz: Quiz, q: Question, seed: str | int | None,
                     loc: Localizer) -> tuple[OptionView, ...]:
        """What the student chooses from, translated, in this attempt's order."""
        return tuple(OptionView(o.id, loc.option(q, o)) for o in self.option_order(quiz, q, seed))

    # The terminal (``quiz take``) -------------------------------------------------------

    def terminal_lines(self, view: QuestionView) -> list[str]:
        """What follows the question's text and code: numbered options, then the unit."""
        lines = [f"  {i}) {terminal(o.text)}" for i, o in enumerate(view.options, 1)]
        if view.unit:
            lines.append(f"  [{terminal(view.unit)}]")
        return lines

    @abc.abstractmethod
    def prompt(self, view: QuestionView) -> str:
        """What the prompt asks for (Enter always skips)."""

    @abc.abstractmethod
    def parse_terminal(self, view: QuestionView, raw: str) -> Any:
        """The answer typed (stripped, not empty), in the answers-file shape; ValueError
        if it is not an answer to this question (the student is asked again)."""

    # The web form (``quiz serve``) ------------------------------------------------------

    @abc.abstractmethod
    def parse_form(self, q: Question, form: Form) -> Any | None:
        """The answer in a submitted form, in the answers-file shape; None if left blank."""

    def form_problem(self, q: Question, form: Form) -> str | None:
        """Why what was entered for ``q`` is no answer (``five`` in a number box), for the
        page to say so at the question; None when it reads, or was left blank."""
        return None

    # The Markdown export ----------------------------------------------------------------

    @abc.abstractmethod
    def markdown_lines(self, view: QuestionView) -> list[str]:
        """Markdown lines under the question's text and code, ending with a blank line."""

    # The LMS exports (``quiz export``) --------------------------------------------------

    def moodle_question(self, q: Question, moodle: MoodleWriter) -> El:
        """The question in Moodle XML, made with ``moodle``'s builders (``multichoice``,
        ``truefalse``, ``numerical``, ``ordering``; ``note`` for a scoring Moodle cannot
        match).  A type without one stops the export with a message naming the question."""
        raise moodle.unsupported(q)

    def qti_item(self, q: Question, qti: QtiWriter) -> QtiItem:
        """The question as a QTI 2.1 item, made with ``qti``'s builders (``choice``,
        ``order``, ``numeric``).  A type without one stops the export, as above."""
        raise qti.unsupported(q)


# Shared by the types whose answer names options --------------------------------------------


def one_option_problem(q: Question, value: Any) -> str | None:
    """An answer naming exactly one option id."""
    if not isinstance(value, str):
        return _("question {id!r} needs one option id, found {value!r}").format(
            id=q.id, value=value)
    return unknown_option_problem(q, [value])


def option_list_problem(q: Question, value: Any) -> str | None:
    """An answer that is a list of option ids, none twice."""
    if not isinstance(value, list):
        return _("question {id!r} needs a list of option ids, found {value!r}").format(
            id=q.id, value=value)
    problem = unknown_option_problem(q, value)
    if problem is None and len(set(value)) != len(value):
        return _("question {id!r} names an option twice").format(id=q.id)
    return problem


def unknown_option_problem(q: Question, chosen: list[Any]) -> str | None:
    ids = q.option_ids
    for option in chosen:
        if option not in ids:
            return _("question {id!r} has no option {option!r} (options: {ids})").format(
                id=q.id, option=option, ids=", ".join(ids))
    return None


def check_option_list_key(doc: Document, q: Question, where: Where) -> list[str]:
    """A key that is a list of option ids, each known, none twice; returned for more checks."""
    a, at, ids = q.answer, (*where, "answer"), q.option_ids
    if not isinstance(a, list) or not all(isinstance(x, str) for x in a):
        raise doc.error(_("the key must be a list of option ids, found {value!r}").format(
            value=a), *at)
    unknown = [x for x in a if x not in ids]
    if unknown:
        raise doc.error(_("the key names no option {id!r} (options: {ids})").format(
            id=unknown[0], ids=", ".join(ids)), *at)
    if len(set(a)) != len(a):
        raise doc.error(_("the key names an option twice"), *at)
    return a


def picked_ids(view: QuestionView, raw: str) -> list[str]:
    """Option numbers as typed ("2", "1,3", "3 1 2") turned into ids, each once."""
    n = len(view.options)
    picks = [int(x) for x in raw.replace(",", " ").split()]
    if not picks or any(not 1 <= p <= n for p in picks) or len(set(picks)) != len(picks):
        raise ValueError(raw)
    return [view.options[p - 1].id for p in picks]


def one_picked_id(view: QuestionView, raw: str) -> str:
    ids = picked_ids(view, raw)
    if len(ids) != 1:
        raise ValueError(raw)
    return ids[0]


def first_value(q: Question, form: Form) -> str | None:
    """The first non-empty value submitted for ``q:<id>``."""
    values = [v for v in form.get(f"q:{q.id}", []) if v]
    return values[0] if values else None
