"""``autograder quiz``: list, lint, render, export, take, score, key and serve quizzes.

A thin click layer: each command calls a plain function of :mod:`autograder.commands.quiz`
and prints what it returns; every bad input becomes one line naming the file (see
``autograder.cli.exits``).
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from pathlib import Path
from typing import Any, TypeVar

import click

from autograder.cli.exits import GraderFault, UsageProblem, report_problems
from autograder.commands import quiz as commands
from autograder.commands.written import say_written
from autograder.core.errors import ContentError, GraderError, UsageError
from autograder.i18n import LANGUAGES, _, get_language, set_language

F = TypeVar("F", bound=Callable[..., Any])


def _errors(func: F) -> F:
    """Turn bad input (a bad quiz, answers or catalog file) into a one-line exit 2 and our
    own failure into exit 3, also when the group is invoked on its own (tests, tools);
    restore the language the command found when it ends."""

    @functools.wraps(func)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        before = get_language()
        ctx = click.get_current_context(silent=True)
        if ctx is not None:  # restore when the command ends (matters when invoked in-process)
            ctx.call_on_close(lambda: set_language(before))
        try:
            return func(*args, **kwargs)
        except commands.NotLoaded as exc:
            for line in exc.earlier:
                click.echo(line, err=True)
            raise UsageProblem(str(exc)) from None
        except (ContentError, UsageError) as exc:
            raise UsageProblem(str(exc)) from None
        except GraderError as exc:
            raise GraderFault(str(exc)) from None

    return wrapper  # type: ignore[return-value]


class _Terminal:
    """The :class:`~autograder.commands.quiz.Console` of a user at a terminal."""

    def say(self, text: str, *, err: bool = False) -> None:
        click.echo(text, err=err)

    def ask(self, prompt: str) -> str:
        return str(click.prompt(prompt, default="", show_default=False))


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
    text = commands.quiz_list(as_json)
    if text:
        click.echo(text)


@quiz_cli.command("lint")
@_errors
def lint_command() -> None:
    """Check every quiz and its translations; print file:line: message for each problem."""
    report_problems(commands.lint_problems())
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
    for path in commands.render_quizzes(quizzes, lang, fmt, seed, out):
        click.echo(str(path))


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
    for path in commands.export_quizzes(quizzes, fmt, lang, out):
        click.echo(str(path))


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
    scored = commands.score_answers(quiz, answers, _given_language(lang), results, html)
    say_written(scored.written)
    if as_json:
        click.echo(scored.data)
        return
    if scored.notice:
        click.echo(scored.notice, err=True)
    click.echo(scored.summary)


@quiz_cli.command("key")
@click.argument("quiz")
@_errors
def key_command(quiz: str) -> None:
    """Print the answers file that scores full marks (for instructors)."""
    click.echo(commands.answer_key(quiz))


@quiz_cli.command("take")
@click.argument("quiz")
@_lang_option
@click.option("--seed", default=None, help="Shuffle options with this seed (default: random).")
@click.option("--save", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="Save your answers file here.")
@_errors
def take_command(quiz: str, lang: str | None, seed: str | None, save: Path | None) -> None:
    """Take QUIZ in the terminal."""
    commands.take_quiz(_Terminal(), quiz, lang, seed, save)


@quiz_cli.command("serve")
@click.option("--port", type=int, default=8765, show_default=True,
              help="Port on 127.0.0.1 (0 picks a free one).")
@_lang_option
@_errors
def serve_command(port: int, lang: str | None) -> None:
    """Serve the quizzes on http://127.0.0.1:PORT/ for a browser."""
    commands.serve_quizzes(_Terminal(), port, lang)
