"""A quiz file parsed into frozen dataclasses, with every key checked against its options.

The answer key names option ids, never positions or text, so shuffling and translation
cannot break it.  A malformed file is a :class:`~autograder.core.errors.ContentError`
naming the file, the line and the field.  What a key and options must look like is up to
the question's type (``autograder.quiz.types``); the checks here hold for every type.
"""

from __future__ import annotations

import dataclasses
import re
from collections.abc import Iterator
from fractions import Fraction
from pathlib import Path
from typing import Any

from autograder.core.errors import ContentError
from autograder.core.results import exact
from autograder.i18n import _
from autograder.quiz.types import question_type, registry
from content import Document, build, load_document

ID_PATTERN = re.compile(r"^[a-z0-9][a-z0-9_-]*$")


def _doc(text: str) -> dict[str, str]:
    return {"doc": text}


@dataclasses.dataclass(frozen=True)
class Option:
    """One option of a choice question, or one item of an ordering question."""

    id: str = dataclasses.field(default="", metadata=_doc(
        "Stable id, unique in the question; the key names it."))
    text: str = dataclasses.field(default="", metadata=_doc(
        "What the student reads; `backticks` mark code."))
    pin: bool = dataclasses.field(default=False, metadata=_doc(
        "Keep this option where it is when options shuffle (for 'none of the above')."))


@dataclasses.dataclass(frozen=True)
class Question:
    """One question; ``answer`` is the key and never reaches a student."""

    id: str = dataclasses.field(default="", metadata=_doc("Stable id, unique in the quiz."))
    type: str = dataclasses.field(default="single", metadata=_doc(
        "A question type of autograder.quiz.types: single, multiple, true_false, numeric "
        "or ordering as shipped."))
    text: str = dataclasses.field(default="", metadata=_doc(
        "The question; `backticks` mark inline code."))
    code: str = dataclasses.field(default="", metadata=_doc(
        "An optional code block shown under the question (not translated)."))
    options: tuple[Option, ...] = dataclasses.field(default=(), metadata=_doc(
        "Options (single, multiple) or items to put in order (ordering)."))
    answer: Any = dataclasses.field(default=None, metadata=_doc(
        "The key: an option id (single), a list of ids (multiple; ordering, in order), "
        "true or false (true_false), a number (numeric)."))
    tolerance: float = dataclasses.field(default=0.0, metadata=_doc(
        "numeric: an answer within this distance of the key is right."))
    unit: str = dataclasses.field(default="", metadata=_doc("numeric: unit shown after the box."))
    partial_credit: bool = dataclasses.field(default=False, metadata=_doc(
        "multiple: proportional credit, (right picked - wrong picked) / right, at least 0."))
    points: int = dataclasses.field(default=1, metadata=_doc("What the question is worth."))
    explanation: str = dataclasses.field(default="", metadata=_doc(
        "Shown with the feedback after the quiz is submitted."))

    @property
    def option_ids(self) -> tuple[str, ...]:
        """The ids an answer may name (for true_false: ``true`` and ``false``)."""
        return question_type(self.type).option_ids(self)

    def key(self) -> Any:
        """The key as an answers file states it (option ids, never booleans)."""
        return question_type(self.type).key(self)


@dataclasses.dataclass(frozen=True)
class Quiz:
    """A quiz for one part of the chapter."""

    id: str = dataclasses.field(default="", metadata=_doc("Stable id, unique in the course."))
    title: str = dataclasses.field(default="", metadata=_doc("Title students see."))
    summary: str = dataclasses.field(default="", metadata=_doc(
        "One or two lines on what it covers."))
    pass_mark: float = dataclasses.field(default=0.7, metadata=_doc(
        "Fraction of the points needed to pass: 0.7 is 70%."))
    languages: tuple[str, ...] = dataclasses.field(default=("en", "ur"), metadata=_doc(
        "Languages the quiz is offered in; lint checks each one's catalog."))
    questions: tuple[Question, ...] = dataclasses.field(default=(), metadata=_doc(
        "The questions, in the order they are asked."))

    @property
    def exact_pass_mark(self) -> Fraction:
        return exact(self.pass_mark)

    @property
    def max_score(self) -> int:
        return sum(q.points for q in self.questions)

    def question(self, question_id: str) -> Question | None:
        return next((q for q in self.questions if q.id == question_id), None)


@dataclasses.dataclass(frozen=True)
class QuizFile:
    """A loaded quiz and the document it came from (for line numbers)."""

    path: Path
    quiz: Quiz
    doc: Document

    def line(self, *where: str | int) -> int:
        return self.doc.line(*where) or 1


@dataclasses.dataclass(frozen=True)
class SourceString:
    """A translatable string of a quiz: its gettext context, text and line."""

    context: str
    text: str
    line: int
    comment: str


def context(quiz_id: str, *parts: str) -> str:
    """The gettext context of a quiz string: ``quiz:<quiz>[:<question>]:<field>``."""
    return ":".join(("quiz", quiz_id, *parts))


def is_code_only(text: str) -> bool:
    """A string that is a single code span (or empty) is never translated."""
    return not text.strip() or re.fullmatch(r"\s*`[^`]+`\s*", text) is not None


def strings(qf: QuizFile) -> Iterator[SourceString]:
    """Every translatable string of a quiz, in file order."""
    quiz = qf.quiz
    for name in ("title", "summary"):
        text = getattr(quiz, name)
        if not is_code_only(text):
            yield SourceString(context(quiz.id, name), text, qf.line(name), f"quiz {name}")
    for i, q in enumerate(quiz.questions):
        for name in ("text", "unit", "explanation"):
            text = getattr(q, name)
            if not is_code_only(text):
                yield SourceString(context(quiz.id, q.id, name), text,
                                   qf.line("questions", i, name), f"{q.type} question, {name}")
        for j, o in enumerate(q.options):
            if not is_code_only(o.text):
                yield SourceString(context(quiz.id, q.id, f"options.{o.id}"), o.text,
                                   qf.line("questions", i, "options", j, "text"),
                                   f"{q.type} question, option {o.id}")


def load_quiz(path: Path | str, text: str | None = None) -> QuizFile:
    """Read and check a quiz file; raise ContentError on the first problem."""
    doc = load_document(path, text)
    quiz = build(Quiz, doc, doc.data)
    _check(doc, quiz)
    return QuizFile(Path(path), quiz, doc)


def check_id(doc: Document, value: str, *where: str | int) -> None:
    """Ids (of quizzes, questions, options) are lower-case words, safe in URLs and forms."""
    if not ID_PATTERN.match(value):
        raise doc.error(_("id {id!r} must be lower-case letters, digits, '-' or '_'").format(
            id=value), *where)


def _check(doc: Document, quiz: Quiz) -> None:
    """Checks no dataclass type can state: ids unique, keys valid, numbers sane."""
    types = registry()
    for i, q in enumerate(quiz.questions):  # first: every later check goes through the type
        if q.type not in types:
            raise doc.error(_("must be one of {allowed}, found {value!r}").format(
                allowed=", ".join(repr(name) for name in sorted(types)), value=q.type),
                "questions", i, "type")
    check_id(doc, quiz.id, "id")
    if not quiz.title.strip():
        raise doc.error(_("required field is missing"), "title")
    if not 0 < quiz.pass_mark <= 1:
        raise doc.error(_("must be above 0 and at most 1 (0.7 is 70%), found {value!r}").format(
            value=quiz.pass_mark), "pass_mark")
    if not quiz.questions:
        raise doc.error(_("a quiz needs at least one question"), "questions")
    seen: set[str] = set()
    for i, q in enumerate(quiz.questions):
        where = ("questions", i)
        if not q.id:
            raise doc.error(_("required field is missing"), *where, "id")
        check_id(doc, q.id, *where, "id")
        if q.id in seen:
            raise doc.error(_("duplicate question id {id!r}").format(id=q.id), *where, "id")
        seen.add(q.id)
        if not q.text.strip():
            raise doc.error(_("required field is missing"), *where, "text")
        if q.points < 1:
            raise doc.error(_("must be at least 1, found {value!r}").format(value=q.points),
                            *where, "points")
        kind = types[q.type]
        kind.check_options(doc, q, where)
        if q.answer is None:
            raise doc.error(_("every question needs an answer key"), *where, "answer")
        kind.check_key(doc, q, where)
        for other in types.values():  # a field only other types use, set here by mistake
            for name, message in other.owned_fields.items():
                if name not in kind.owned_fields and getattr(q, name):
                    raise doc.error(_(message), *where, name)


def check_ids_unique(files: list[QuizFile]) -> list[ContentError]:
    """Quiz ids must be unique across the course."""
    seen: dict[str, QuizFile] = {}
    problems = []
    for qf in files:
        other = seen.get(qf.quiz.id)
        if other is not None:
            problems.append(ContentError(qf.path, _("quiz id {id!r} is also used by {other}")
                                         .format(id=qf.quiz.id, other=other.path),
                                         qf.line("id"), "id"))
        seen.setdefault(qf.quiz.id, qf)
    return problems

