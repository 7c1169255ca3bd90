"""``autograder quiz``: what each of its commands does, as plain functions that return what
is to be printed (``take`` and ``serve`` talk through a :class:`Console`). Bad input (a
malformed or missing quiz, answers or catalog file, a port in use) is a
:class:`~autograder.core.errors.UsageError` or a :class:`~autograder.core.errors.ContentError`;
the CLI turns them into exit codes.
"""

from __future__ import annotations

import json
import textwrap
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

from autograder.core.errors import ContentError, UsageError
from autograder.i18n import _, get_language, locales_dir, set_language
from autograder.i18n.text import Text, format_number, format_percent, terminal
from autograder.i18n.tools import read_catalog
from autograder.quiz import CONTENT_DOMAIN
from autograder.quiz.catalog import find_quiz, list_quizzes, load_each
from autograder.quiz.localize import Localizer, require_translation
from autograder.quiz.render import render_markdown, render_page, render_result
from autograder.quiz.scoring import (
    file_key,
    pass_summary,
    read_answers,
    recorded_language,
    result_dict,
    score,
)
from autograder.quiz.types import question_type
from autograder.quiz.views import question_views
from autograder.render.terminal import for_terminal, rtl_notice

if TYPE_CHECKING:
    from autograder.core.results import RunResult
    from autograder.quiz.lint import Problem
    from autograder.quiz.model import Quiz, QuizFile
    from autograder.quiz.types.base import QuestionType
    from autograder.quiz.views import QuestionView

__all__ = [
    "SHORT", "Console", "NotLoaded", "Scored", "answer_key", "export_quizzes", "lint_problems",
    "quiz_list", "render_quizzes", "score_answers", "serve_quizzes", "summary", "take_quiz",
    "use_language",
]


class NotLoaded(UsageError):
    """Quiz files that did not load, reported once the others are done: the message names
    the last; :attr:`earlier` holds a line for each of the others, to be printed first."""

    def __init__(self, broken: Sequence[ContentError]) -> None:
        super().__init__(_("not loaded: {error}").format(error=broken[-1]))
        self.earlier = [_("not loaded: {error}").format(error=exc) for exc in broken[:-1]]


class Console(Protocol):
    """Where an interactive command talks to its user (the terminal, or a test's script)."""

    def say(self, text: str, *, err: bool = False) -> None:
        """Print one line (on stderr when ``err``)."""

    def ask(self, prompt: str) -> str:
        """Prompt and return what the user typed ("" when they only pressed Enter)."""


def use_language(lang: str | None) -> str:
    """Make ``lang`` (None: the active one) the active language and check its catalogs:
    a malformed catalog is a ContentError naming its line, not a traceback later on."""
    lang = lang or get_language()
    set_language(lang)
    if lang != "en":
        for domain in (CONTENT_DOMAIN, "messages"):
            po = locales_dir() / lang / "LC_MESSAGES" / f"{domain}.po"
            if po.exists():
                read_catalog(po, lang)
    return lang


def quiz_list(as_json: bool) -> str:
    """The quizzes with their ids, titles and languages: one line each, or JSON for tools."""
    entries = list_quizzes()
    if as_json:
        return json.dumps([{"id": e.id, "title": e.title, "languages": list(e.languages),
                            **({"error": e.error} if e.error else {})}
                           for e in entries], ensure_ascii=False, indent=2)
    return "\n".join(f"{e.id}  {e.title}  [{', '.join(e.languages)}]" if not e.error else
                     f"{e.id}  " + _("not loaded: {error}").format(error=e.error)
                     for e in entries)


def lint_problems() -> list[Problem]:
    """Each problem of every quiz and its translations (``file:line: message``)."""
    from autograder.quiz.lint import lint

    return lint()


def _named_or_each(quizzes: Sequence[str]) -> tuple[list[QuizFile], list[ContentError]]:
    """The quizzes named (a broken one is the command's error), or every quiz that loads
    and the error of each file that does not."""
    if quizzes:
        return [find_quiz(q) for q in quizzes], []
    return load_each()


def render_quizzes(quizzes: Sequence[str], lang: str | None, fmt: str, seed: str | None,
                   out: Path) -> Iterator[Path]:
    """Write QUIZ.LANG.html and/or QUIZ.LANG.mdx (``fmt``: html, md, both) into ``out``
    for the quizzes named (every quiz by default) in ``lang`` (each quiz's languages by
    default); yield each file as it is written, then raise :class:`NotLoaded` if a quiz
    file was left out."""
    files, broken = _named_or_each(quizzes)
    out.mkdir(parents=True, exist_ok=True)
    for qf in files:
        for code in (lang,) if lang else qf.quiz.languages:
            use_language(code)
            require_translation(qf, code)
            if fmt in ("html", "both"):
                path = out / f"{qf.quiz.id}.{code}.html"
                path.write_text(render_page(qf.quiz, code, seed), encoding="utf-8")
                yield path
            if fmt in ("md", "both"):
                path = out / f"{qf.quiz.id}.{code}.mdx"
                path.write_text(render_markdown(qf.quiz, code, seed), encoding="utf-8")
                yield path
    if broken:
        raise NotLoaded(broken)


def export_quizzes(quizzes: Sequence[str], fmt: str, lang: str | None,
                   out: Path | None) -> Iterator[Path]:
    """Write the quizzes named (every quiz by default) as one Moodle XML file (``fmt``
    moodle-xml: every language the quiz lists, or ``lang``'s) or one QTI 2.1 package
    (qti: ``lang``'s, English by default); yield the file written, then raise
    :class:`NotLoaded` if a quiz file was left out."""
    from autograder.quiz.export import export_moodle_xml, export_qti

    use_language(lang)
    files, broken = _named_or_each(quizzes)
    if not files and broken:
        raise NotLoaded(broken)
    for qf in files:
        for code in ((lang or "en",) if fmt == "qti" else (lang,) if lang else qf.quiz.languages):
            require_translation(qf, code)
    name = files[0].quiz.id if len(files) == 1 else "quizzes"
    data: str | bytes
    if fmt == "moodle-xml":
        data = export_moodle_xml(files, (lang,) if lang else None)
        out = out or Path("out/quizzes") / f"{name}.moodle.xml"
    else:
        data = export_qti(files, lang or "en")
        out = out or Path("out/quizzes") / f"{name}.{lang or 'en'}.qti.zip"
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        if isinstance(data, str):
            out.write_text(data, encoding="utf-8")
        else:
            out.write_bytes(data)
    except OSError as exc:
        raise UsageError(_("cannot write {path}: {error}").format(
            path=out, error=exc.strerror or exc)) from None
    yield out
    if broken:
        raise NotLoaded(broken)


SHORT = 72
"""Question and answer texts in a result are cut to this many characters: enough to know
the question again; its whole text is on the quiz's page."""


def _short(text: str) -> str:
    short = textwrap.shorten(text, SHORT, placeholder=" …")
    if short.count("`") % 2:  # a code span cut in two: its opening backtick goes too
        head, _tick, tail = short.rpartition("`")
        short = head + tail
    return short


def summary(quiz: Quiz, result: RunResult) -> str:
    """The score in the terminal: per question its text (shortened), the verdict on the
    student's answer and the answer itself, the explanation when it was not right; then
    the verdict and the pass mark."""
    lang = result.lang
    loc = Localizer(quiz, lang)
    lines = [result.title, ""]
    for n, t in enumerate(result.tests, 1):
        mark = "✔" if t.status == "passed" else "✘"
        lines.append(f" {mark} {format_number(n, lang)}. {_short(terminal(Text(t.label, lang)))} "
                     f"({format_number(t.score, lang)}/{format_number(t.max_score, lang)})")
        answer = t.answer
        said = t.message
        question = quiz.question(t.name)
        if answer is not None and question is not None:
            text = question_type(question.type).answer_text(quiz, question, answer, loc)
            said += " " + _("Your answer: {answer}").format(answer=_short(text))
        lines.append("      " + said)
        if t.status != "passed" and t.hint:
            lines.append("      " + " ".join(t.hint.split()))
    verdict = _("Passed") if result.passed else _("Not passed yet")
    lines += ["", _("{verdict}: {score} of {max_score} ({percent})").format(
        verdict=verdict, score=format_number(result.score, lang),
        max_score=format_number(result.max_score, lang),
        percent=format_percent(result.fraction, lang)), pass_summary(quiz, lang)]
    return for_terminal("\n".join(lines), lang)


@dataclass(frozen=True)
class Scored:
    """What ``quiz score`` prints: the results JSON, the terminal summary, the note on
    right-to-left text (or ""), and the files written as (option name, path)."""

    data: str
    summary: str
    notice: str | None
    written: tuple[tuple[str, Path], ...]


def score_answers(quiz: str, answers: Path, lang: str | None, results: Path | None,
                  html: Path | None) -> Scored:
    """Score a student's ``answers`` file for ``quiz`` in ``lang``, else in the language
    the file was taken in; write the results JSON and the result page where asked."""
    qf = find_quiz(quiz)
    lang = use_language(lang or recorded_language(answers, qf.quiz))
    given = read_answers(answers, qf.quiz)
    result = score(qf.quiz, given, lang)
    data = json.dumps(result_dict(result), ensure_ascii=False, indent=2)
    if results:
        results.parent.mkdir(parents=True, exist_ok=True)
        results.write_text(data + "\n", encoding="utf-8")
    if html:
        html.parent.mkdir(parents=True, exist_ok=True)
        html.write_text(render_result(qf.quiz, result, given, retake=False), encoding="utf-8")
    written = tuple((name, path) for name, path in (("results", results), ("html", html))
                    if path)
    return Scored(data, summary(qf.quiz, result), rtl_notice(lang, html=html), written)


def answer_key(quiz: str) -> str:
    """The answers file (JSON) that scores full marks on ``quiz``."""
    return json.dumps(file_key(find_quiz(quiz).quiz), ensure_ascii=False, indent=2)


def _ask(console: Console, kind: QuestionType, view: QuestionView) -> Any:
    """Prompt until the answer parses; Enter skips the question."""
    while True:
        raw = console.ask(kind.prompt(view)).strip()
        if not raw:
            return None
        try:
            return kind.parse_terminal(view, raw)
        except ValueError:
            console.say(_("That is not an answer to this question; try again."), err=True)


def take_quiz(console: Console, quiz: str, lang: str | None, seed: str | None,
              save: Path | None) -> None:
    """Put each question of ``quiz`` to the user in ``lang`` (None: the active language;
    options shuffled with ``seed``, random by default), then show the score; save the
    answers file if asked."""
    import secrets

    lang = use_language(lang)
    qf = find_quiz(quiz)
    seed = seed if seed is not None else str(secrets.randbelow(10**9))
    loc = Localizer(qf.quiz, lang)
    console.say(for_terminal(terminal(loc.quiz_text("title"))))
    console.say(for_terminal(pass_summary(qf.quiz, lang)))
    notice = rtl_notice(lang, serve=True)
    if notice:
        console.say(notice)
    answers: dict[str, Any] = {}
    for view in question_views(qf.quiz, lang, seed):
        console.say("")
        console.say(for_terminal(f"{view.number}. {terminal(view.text)}"))
        if view.code:
            console.say("\n".join("    " + line for line in view.code.splitlines()))
        kind = question_type(view.type)
        for line in kind.terminal_lines(view):
            console.say(for_terminal(line))
        value = _ask(console, kind, view)
        if value is not None:
            answers[view.id] = value
    result = score(qf.quiz, answers, lang)
    console.say("")
    console.say(summary(qf.quiz, result))
    if save:
        save.write_text(json.dumps({"quiz": qf.quiz.id, "seed": seed, "lang": lang,
                                    "answers": answers}, ensure_ascii=False, indent=2) + "\n",
                        encoding="utf-8")
        console.say(_("Answers saved to {path}").format(path=save))


def serve_quizzes(console: Console, port: int, lang: str | None) -> None:
    """Serve every quiz that loads on http://127.0.0.1:``port``/ (0 picks a free port)
    in ``lang`` (None: the active language) until Ctrl-C; name each file left out."""
    from autograder.quiz.server import QuizServer

    lang = use_language(lang)
    files, errors = load_each()
    for exc in errors:  # served without it; the others are unaffected
        console.say(_("not loaded: {error}").format(error=exc), err=True)
    try:
        server = QuizServer(files, port, lang)
    except OSError as exc:
        raise UsageError(_("cannot listen on 127.0.0.1:{port}: {error}").format(
            port=port, error=exc.strerror or exc)) from None
    console.say(_("Quizzes at {url} (Ctrl-C stops the server)").format(url=server.url))
    try:
        server.serve_forever()
    except KeyboardInterrupt:
        pass
    finally:
        server.server_close()
