"""Score an answers file against a quiz, exactly, into the one results model.

A bad answers file is a :class:`~autograder.core.errors.ContentError` naming the file
and the line, as a bad quiz file is; each question's type checks and scores its answer.
"""

from __future__ import annotations

import json
import math
import re
from collections.abc import Mapping
from fractions import Fraction
from pathlib import Path
from typing import Any

from autograder.core.errors import ContentError
from autograder.core.results import RunResult, TestResult
from autograder.i18n import _, ngettext
from autograder.i18n.text import format_number, format_percent, using_language
from autograder.quiz.localize import Localizer
from autograder.quiz.model import Quiz
from autograder.quiz.types import question_type

ANSWERS_KEYS = {"quiz", "answers", "seed", "lang", "student"}


def _line_of(text: str, key: str) -> int | None:
    """Line of ``"key"`` in JSON text: good enough to point a student at the mistake."""
    match = re.search(re.escape(json.dumps(key)), text)
    return text.count("\n", 0, match.start()) + 1 if match else None


def read_answers(path: Path | str, quiz: Quiz, text: str | None = None) -> dict[str, Any]:
    """Read and check an answers file for ``quiz``; return its ``answers`` mapping."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8") if text is None else text
    except FileNotFoundError:
        raise ContentError(path, _("file not found")) from None
    except (OSError, UnicodeDecodeError) as exc:
        raise ContentError(path, _("cannot read file: {error}").format(error=exc)) from None
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise ContentError(path, _("not valid JSON: {problem} (column {column})").format(
            problem=exc.msg, column=exc.colno), exc.lineno) from None
    return check_answers(path, quiz, data, text)


def recorded_language(path: Path | str, quiz: Quiz) -> str | None:
    """The language an answers file says the quiz was taken in (its ``lang``), if the quiz
    has it; None otherwise (a file that cannot be read is :func:`read_answers`' to report)."""
    try:
        data = json.loads(Path(path).read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, ValueError):
        return None
    lang = data.get("lang") if isinstance(data, dict) else None
    return lang if isinstance(lang, str) and lang in quiz.languages else None


def check_answers(path: Path | str, quiz: Quiz, data: Any, text: str = "") -> dict[str, Any]:
    """Check the shape of decoded answers; the error names the file, line and id."""
    if not isinstance(data, dict) or not isinstance(data.get("answers"), dict):
        raise ContentError(path, _('must be a JSON object `{{"quiz": ..., "answers": {{...}}}}`')
                           .format())
    unknown = sorted(set(data) - ANSWERS_KEYS)
    if unknown:
        raise ContentError(path, _("unknown key {key!r} (expected: {known})").format(
            key=unknown[0], known=", ".join(sorted(ANSWERS_KEYS))), _line_of(text, unknown[0]))
    if data.get("quiz") != quiz.id:
        raise ContentError(path, _("answers quiz {found!r}, not {expected!r}").format(
            found=data.get("quiz"), expected=quiz.id), _line_of(text, "quiz"))
    answers: dict[str, Any] = data["answers"]
    for qid, value in answers.items():
        q = quiz.question(qid)
        line = _line_of(text, qid)
        if q is None:
            raise ContentError(path, _("no question {id!r} in quiz {quiz!r}").format(
                id=qid, quiz=quiz.id), line)
        problem = question_type(q.type).answer_problem(q, value)
        if problem:
            raise ContentError(path, problem, line)
    return answers


def needed_to_pass(quiz: Quiz) -> int:
    """Fewest points that pass: the smallest n with n / max >= pass mark."""
    return math.ceil(quiz.exact_pass_mark * quiz.max_score)


def pass_summary(quiz: Quiz, lang: str) -> str:
    """'Passing score: 70% (4/5 questions)', as the chapter says it, in ``lang``."""
    total = quiz.max_score
    all_single = all(q.points == 1 for q in quiz.questions)
    with using_language(lang):
        return _pass_summary(quiz, lang, total, all_single)


def _pass_summary(quiz: Quiz, lang: str, total: int, all_single: bool) -> str:
    counted = (ngettext("{needed}/{total} question", "{needed}/{total} questions", total)
               if all_single else
               ngettext("{needed}/{total} point", "{needed}/{total} points", total))
    return _("Passing score: {percent} ({counted})").format(
        percent=format_percent(quiz.exact_pass_mark, lang),
        counted=counted.format(needed=format_number(needed_to_pass(quiz), lang),
                               total=format_number(total, lang)))


def score(quiz: Quiz, answers: Mapping[str, Any], lang: str = "en") -> RunResult:
    """Score checked answers; a question left out scores 0.  Messages are in ``lang``."""
    with using_language(lang):
        return _score(quiz, answers, lang)


def _score(quiz: Quiz, answers: Mapping[str, Any], lang: str) -> RunResult:
    loc = Localizer(quiz, lang)
    tests = []
    for q in quiz.questions:
        value = answers.get(q.id)
        kind = question_type(q.type)
        points = Fraction(q.points)
        earned = Fraction(0) if value is None else kind.credit(q, value) * points
        tests.append(TestResult(
            name=q.id, label=loc.text(q, "text").value, score=earned, max_score=points,
            status="passed" if earned == points else "failed",
            message=kind.feedback(q, value, earned, lang),
            hint=loc.text(q, "explanation").value if q.explanation else "",
            answer=value))
    return RunResult(kind="quiz", id=quiz.id, title=loc.quiz_text("title").value,
                     tests=tuple(tests), pass_mark=quiz.exact_pass_mark, lang=lang,
                     pass_summary=pass_summary(quiz, lang))


def result_dict(result: RunResult) -> dict[str, Any]:
    """The results JSON: the shared shape, plus the pass summary the chapter prints."""
    out = result.to_dict()
    out["pass_summary"] = result.pass_summary
    return out


def key_answers(quiz: Quiz) -> dict[str, Any]:
    """The answers file that scores full marks (for instructors only)."""
    return {"quiz": quiz.id, "answers": {q.id: q.key() for q in quiz.questions}}


def file_key(quiz: Quiz) -> dict[str, Any]:
    """The answers file that scores full marks, each answer as the quiz file states its key
    (``false``, not ``"false"``), so that it also pastes back into ``answer:``."""
    return {"quiz": quiz.id, "answers": {
        q.id: list(q.answer) if isinstance(q.answer, tuple) else q.answer
        for q in quiz.questions}}
