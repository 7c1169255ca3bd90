"""A quiz file parsed into frozen dataclasses, with every key checked against its options.

The answer key names option ids, never positions or text, so shuffling and translation
cannot break it.  A malformed file is a :class:`~autograder.core.errors.ContentError`
naming the file, the line and the field.
"""

from __future__ import annotations

import dataclasses
import math
import re
from collections.abc import Iterator
from fractions import Fraction
from pathlib import Path
from typing import Any, Literal

from autograder.core.errors import ContentError
from autograder.core.results import exact
from autograder.i18n import _
from sim.content import Document, build, load_document

QuestionType = Literal["single", "multiple", "true_false", "numeric", "ordering"]
ID_PATTERN = re.compile(r"^[a-z0-9][a-z0-9_-]*$")
TRUE_FALSE_IDS = ("true", "false")


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
    type: QuestionType = dataclasses.field(default="single", metadata=_doc(
        "single, multiple, true_false, numeric or ordering."))
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
        if self.type == "true_false":
            return TRUE_FALSE_IDS
        return tuple(o.id for o in self.options)

    def key(self) -> Any:
        """The key as an answers file states it (option ids, never booleans)."""
        if self.type == "true_false":
            return "true" if self.answer else "false"
        if isinstance(self.answer, tuple):
            return list(self.answer)
        return self.answer


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


def _check_id(doc: Document, value: str, *where: str | int) -> None:
    if not ID_PATTERN.match(value):
        raise doc.error(_("id {id!r} must be lower-case letters, digits, '-' or '_'").format(
            id=value), *where)


def _check(doc: Document, quiz: Quiz) -> None:
    """Checks no dataclass type can state: ids unique, keys valid, numbers sane."""
    _check_id(doc, quiz.id, "id")
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
        _check_id(doc, q.id, *where, "id")
        if q.id in seen:
            raise doc.error(_("duplicate question id {id!r}").format(id=q.id), *where, "id")
        seen.add(q.id)
        if not q.text.strip():
            raise doc.error(_("required field is missing"), *where, "text")
        if q.points < 1:
            raise doc.error(_("must be at least 1, found {value!r}").format(value=q.points),
                            *where, "points")
        _check_options(doc, q, where)
        _check_key(doc, q, where)


def _check_options(doc: Document, q: Question, where: tuple[str | int, ...]) -> None:
    if q.type in ("true_false", "numeric"):
        if q.options:
            raise doc.error(_("a {type} question has no options").format(type=q.type),
                            *where, "options")
        return
    if len(q.options) < 2:
        raise doc.error(_("needs at least 2 options, found {count}").format(
            count=len(q.options)), *where, "options")
    ids: set[str] = set()
    for j, o in enumerate(q.options):
        if not o.id:
            raise doc.error(_("required field is missing"), *where, "options", j, "id")
        _check_id(doc, o.id, *where, "options", j, "id")
        if o.id in ids:
            raise doc.error(_("duplicate option id {id!r}").format(id=o.id),
                            *where, "options", j, "id")
        ids.add(o.id)
        if not o.text.strip():
            raise doc.error(_("required field is missing"), *where, "options", j, "text")
        if o.pin and q.type == "ordering":
            raise doc.error(_("items of an ordering question cannot be pinned"),
                            *where, "options", j, "pin")


def _check_key(doc: Document, q: Question, where: tuple[str | int, ...]) -> None:
    at = (*where, "answer")
    a = q.answer
    if a is None:
        raise doc.error(_("every question needs an answer key"), *at)
    ids = q.option_ids
    if q.type == "single":
        if not isinstance(a, str) or a not in ids:
            raise doc.error(_("the key must be one option id ({ids}), found {value!r}").format(
                ids=", ".join(ids), value=a), *at)
    elif q.type == "true_false":
        if not isinstance(a, bool):
            raise doc.error(_("the key must be true or false, found {value!r}").format(value=a),
                            *at)
    elif q.type == "numeric":
        if isinstance(a, bool) or not isinstance(a, (int, float)) or not math.isfinite(a):
            raise doc.error(_("the key must be a number, found {value!r}").format(value=a), *at)
        if not math.isfinite(q.tolerance) or q.tolerance < 0:
            raise doc.error(_("the tolerance must be a finite number, 0 or more, "
                              "found {value!r}").format(value=q.tolerance), *where, "tolerance")
    else:
        if not isinstance(a, list) or not all(isinstance(x, str) for x in a):
            raise doc.error(_("the key must be a list of option ids, found {value!r}").format(
                value=a), *at)
        unknown = [x for x in a if x not in ids]
        if unknown:
            raise doc.error(_("the key names no option {id!r} (options: {ids})").format(
                id=unknown[0], ids=", ".join(ids)), *at)
        if len(set(a)) != len(a):
            raise doc.error(_("the key names an option twice"), *at)
        if q.type == "multiple" and not a:
            raise doc.error(_("the key must name at least one option"), *at)
        if q.type == "ordering" and len(a) != len(ids):
            raise doc.error(_("the key must put every item in order ({ids})").format(
                ids=", ".join(ids)), *at)
    if q.type != "numeric" and q.tolerance:
        raise doc.error(_("only a numeric question has a tolerance"), *where, "tolerance")
    if q.type != "multiple" and q.partial_credit:
        raise doc.error(_("only a multiple question gives partial credit"),
                        *where, "partial_credit")


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

