"""``autograder quiz``: list, lint, render, export, take, score, key and serve quizzes.

A thin click layer: each command calls plain functions of the quiz package, and every
bad input becomes one line naming the file (see ``autograder.cli.exits``).
"""

from __future__ import annotations

import functools
import json
import textwrap
from collections.abc import Callable
from pathlib import Path
from typing import Any, TypeVar

import click

from autograder.cli.exits import UsageProblem, report_problems
from autograder.commands.written import say_written
from autograder.core.errors import ContentError
from autograder.core.results import RunResult
from autograder.i18n import (
    LANGUAGES,
    _,
    get_language,
    locales_dir,
    set_language,
)
from autograder.i18n.text import Text, format_number, format_percent, terminal
from autograder.i18n.tools import read_catalog
from autograder.quiz import CONTENT_DOMAIN
from autograder.quiz.catalog import find_quiz, list_quizzes, load_each
from autograder.quiz.localize import Localizer, require_translation
from autograder.quiz.model import Quiz, QuizFile
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
from autograder.quiz.types.base import QuestionType
from autograder.quiz.views import QuestionView, question_views
from autograder.render.terminal import for_terminal, rtl_notice

F = TypeVar("F", bound=Callable[..., Any])


def _errors(func: F) -> F:
    """Turn a bad quiz, answers or catalog file into a one-line ClickException."""

    @functools.wraps(func)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        try:
            return func(*args, **kwargs)
        except ContentError as exc:
            raise UsageProblem(str(exc)) from None

    return wrapper  # type: ignore[return-value]


def _use_lang(lang: str | None) -> str:
    """The command's language (``--lang`` here, else the global one); catalogs checked."""
    before = get_language()
    lang = lang or before
    set_language(lang)
    ctx = click.get_current_context(silent=True)
    if ctx is not None:  # restore when the command ends (matters when invoked in-process)
        ctx.call_on_close(lambda: set_language(before))
    if lang != "en":
        for domain in (CONTENT_DOMAIN, "messages"):
            po = locales_dir() / lang / "LC_MESSAGES" / f"{domain}.po"
            if po.exists():
                read_catalog(po, lang)  # a malformed catalog is an error, not a traceback
    return lang


_lang_option = click.option("--lang", type=click.Choice(LANGUAGES), default=None,
                            help="Language of the quiz and of the messages (en, ur).")


@click.group("quiz")
def quiz_cli() -> None:
    """Take, score, render and check the chapter's quizzes."""


@quiz_cli.command("list")
@click.option("--json", "as_json", is_flag=True, help="Print JSON for tools.")
@_errors
def list_command(as_json: bool) -> None:
    """List the quizzes with their ids, titles and languages."""
    entries = list_quizzes()
    if as_json:
        click.echo(json.dumps([{"id": e.id, "title": e.title, "languages": list(e.languages),
                                **({"error": e.error} if e.error else {})}
                               for e in entries], ensure_ascii=False, indent=2))
        return
    for e in entries:
        click.echo(f"{e.id}  {e.title}  [{', '.join(e.languages)}]" if not e.error else
                   f"{e.id}  " + _("not loaded: {error}").format(error=e.error))


@quiz_cli.command("lint")
@_errors
def lint_command() -> None:
    """Check every quiz and its translations; print file:line: message for each problem."""
    from autograder.quiz.lint import lint

    problems = lint()
    report_problems(problems)
    click.echo(_("All quizzes are complete and translated."))


@quiz_cli.command("render")
@click.argument("quizzes", nargs=-1)
@_lang_option
@click.option("--format", "fmt", type=click.Choice(["html", "md", "both"]), default="both",
              show_default=True, help="HTML page, Markdown/MDX for Docusaurus, or both.")
@click.option("--seed", default=None, help="Shuffle options with this seed.")
@click.option("--out", "out", type=click.Path(file_okay=False, path_type=Path),
              default=Path("out/quizzes"), show_default=True, help="Folder to write to.")
@_errors
def render_command(quizzes: tuple[str, ...], lang: str | None, fmt: str, seed: str | None,
                   out: Path) -> None:
    """Write QUIZ.LANG.html and QUIZ.LANG.mdx (every quiz and language by default)."""
    files, broken = _named_or_each(quizzes)
    langs_for = (lambda quiz: (lang,)) if lang else (lambda quiz: quiz.languages)
    out.mkdir(parents=True, exist_ok=True)
    for qf in files:
        for code in langs_for(qf.quiz):
            _use_lang(code)
            require_translation(qf, code)
            if fmt in ("html", "both"):
                path = out / f"{qf.quiz.id}.{code}.html"
                path.write_text(render_page(qf.quiz, code, seed), encoding="utf-8")
                click.echo(str(path))
            if fmt in ("md", "both"):
                path = out / f"{qf.quiz.id}.{code}.mdx"
                path.write_text(render_markdown(qf.quiz, code, seed), encoding="utf-8")
                click.echo(str(path))
    _left_out(broken)


@quiz_cli.command("export")
@click.argument("quizzes", nargs=-1)
@click.option("--format", "fmt", type=click.Choice(["moodle-xml", "qti"]), required=True,
              help="moodle-xml: one Moodle XML file, every language in multilang spans; "
                   "qti: an IMS QTI 2.1 package (zip) in one language.")
@_lang_option
@click.option("--out", "out", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="File to write (default: out/quizzes/NAME.moodle.xml or "
                   "NAME.LANG.qti.zip, NAME the quiz id, or 'quizzes' for several).")
@_errors
def export_command(quizzes: tuple[str, ...], fmt: str, lang: str | None,
                   out: Path | None) -> None:
    """Write QUIZ (every quiz by default) for Moodle or a QTI 2.1 system such as Canvas.

    moodle-xml carries every language the quiz lists (only --lang's, if given); qti
    carries --lang's (English by default).  Both hold the key: give them to instructors.
    """
    from autograder.quiz.export import export_moodle_xml, export_qti

    _use_lang(lang)
    files, broken = _named_or_each(quizzes)
    if not files:
        _left_out(broken)
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
        raise UsageProblem(_("cannot write {path}: {error}").format(
            path=out, error=exc.strerror or exc)) from None
    click.echo(str(out))
    _left_out(broken)


def _named_or_each(quizzes: tuple[str, ...]) -> tuple[list[QuizFile], list[ContentError]]:
    """The quizzes named (a broken one is the command's error), or every quiz that loads
    and the error of each file that does not."""
    if quizzes:
        return [find_quiz(q) for q in quizzes], []
    return load_each()


def _left_out(broken: list[ContentError]) -> None:
    """After the others are done: name each quiz file that was left out, exit 2."""
    if broken:
        for exc in broken[:-1]:
            click.echo(_("not loaded: {error}").format(error=exc), err=True)
        raise UsageProblem(_("not loaded: {error}").format(error=broken[-1]))


# Question and answer texts in a result are cut to this many characters: enough to know
# the question again; its whole text is on the quiz's page.
SHORT = 72


def _short(text: str) -> str:
    short = textwrap.shorten(text, SHORT, placeholder=" …")
    if short.count("`") % 2:  # a code span cut in two: its opening backtick goes too
        head, _tick, tail = short.rpartition("`")
        short = head + tail
    return short


def _summary(quiz: Quiz, result: RunResult) -> str:
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


def _given_language(lang: str | None) -> str | None:
    """The language asked for on the command line: this command's ``--lang``, else the
    ``autograder --lang`` (or ``AUTOGRADER_LANG``) it runs under; None if neither."""
    if lang:
        return lang
    ctx = click.get_current_context(silent=True)
    return ctx.find_root().params.get("lang") if ctx is not None else None


@quiz_cli.command("score")
@click.argument("quiz")
@click.argument("answers", type=click.Path(path_type=Path))
@_lang_option
@click.option("--results", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="Also write the results JSON here.")
@click.option("--html", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="Also write the result page (score, verdict, feedback) here.")
@click.option("--json", "as_json", is_flag=True, help="Print the results JSON.")
@_errors
def score_command(quiz: str, answers: Path, lang: str | None, results: Path | None,
                  html: Path | None, as_json: bool) -> None:
    """Score a student's ANSWERS file for QUIZ (exit 0 whatever the score), in the
    language the file was taken in unless --lang says otherwise."""
    qf = find_quiz(quiz)
    lang = _use_lang(_given_language(lang) or recorded_language(answers, qf.quiz))
    given = read_answers(answers, qf.quiz)
    result = score(qf.quiz, given, lang)
    data = json.dumps(result_dict(result), ensure_ascii=False, indent=2)
    if results:
        results.parent.mkdir(parents=True, exist_ok=True)
        results.write_text(data + "\n", encoding="utf-8")
    if html:
        html.parent.mkdir(parents=True, exist_ok=True)
        html.write_text(render_result(qf.quiz, result, given, retake=False), encoding="utf-8")
    say_written((name, path) for name, path in (("results", results), ("html", html)) if path)
    if as_json:
        click.echo(data)
        return
    notice = rtl_notice(lang, html=html)
    if notice:
        click.echo(notice, err=True)
    click.echo(_summary(qf.quiz, result))


@quiz_cli.command("key")
@click.argument("quiz")
@_errors
def key_command(quiz: str) -> None:
    """Print the answers file that scores full marks (for instructors)."""
    click.echo(json.dumps(file_key(find_quiz(quiz).quiz), ensure_ascii=False, indent=2))


def _ask(kind: QuestionType, view: QuestionView) -> Any:
    """Prompt until the answer parses; Enter skips the question."""
    while True:
        raw = click.prompt(kind.prompt(view), default="", show_default=False).strip()
        if not raw:
            return None
        try:
            return kind.parse_terminal(view, raw)
        except ValueError:
            click.echo(_("That is not an answer to this question; try again."), err=True)


@quiz_cli.command("take")
@click.argument("quiz")
@_lang_option
@click.option("--seed", default=None, help="Shuffle options with this seed (default: random).")
@click.option("--save", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="Save your answers file here.")
@_errors
def take_command(quiz: str, lang: str | None, seed: str | None, save: Path | None) -> None:
    """Take QUIZ in the terminal."""
    import secrets

    lang = _use_lang(lang)
    qf = find_quiz(quiz)
    seed = seed if seed is not None else str(secrets.randbelow(10**9))
    loc = Localizer(qf.quiz, lang)
    click.echo(for_terminal(terminal(loc.quiz_text("title"))))
    click.echo(for_terminal(pass_summary(qf.quiz, lang)))
    notice = rtl_notice(lang, serve=True)
    if notice:
        click.echo(notice)
    answers: dict[str, Any] = {}
    for view in question_views(qf.quiz, lang, seed):
        click.echo("")
        click.echo(for_terminal(f"{view.number}. {terminal(view.text)}"))
        if view.code:
            click.echo("\n".join("    " + line for line in view.code.splitlines()))
        kind = question_type(view.type)
        for line in kind.terminal_lines(view):
            click.echo(for_terminal(line))
        value = _ask(kind, view)
        if value is not None:
            answers[view.id] = value
    result = score(qf.quiz, answers, lang)
    click.echo("")
    click.echo(_summary(qf.quiz, result))
    if save:
        save.write_text(json.dumps({"quiz": qf.quiz.id, "seed": seed, "lang": lang,
                                    "answers": answers}, ensure_ascii=False, indent=2) + "\n",
                        encoding="utf-8")
        click.echo(_("Answers saved to {path}").format(path=save))


@quiz_cli.command("serve")
@click.option("--port", type=int, default=8765, show_default=True,
              help="Port on 127.0.0.1 (0 picks a free one).")
@_lang_option
@_errors
def serve_command(port: int, lang: str | None) -> None:
    """Serve the quizzes on http://127.0.0.1:PORT/ for a browser."""
    from autograder.quiz.server import QuizServer

    lang = _use_lang(lang)
    files, errors = load_each()
    for exc in errors:  # served without it; the others are unaffected
        click.echo(_("not loaded: {error}").format(error=exc), err=True)
    try:
        server = QuizServer(files, port, lang)
    except OSError as exc:
        raise UsageProblem(_("cannot listen on 127.0.0.1:{port}: {error}").format(
            port=port, error=exc.strerror or exc)) from None
    click.echo(_("Quizzes at {url} (Ctrl-C stops the server)").format(url=server.url))
    try:
        server.serve_forever()
    except KeyboardInterrupt:
        pass
    finally:
        server.server_close()
