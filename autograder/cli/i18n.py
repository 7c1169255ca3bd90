"""``autograder i18n``: extract, update, compile and check the gettext catalogs.

Equivalent pybabel commands are in docs/instructors/translating.md; these read
``babel.cfg`` and write two templates, ``locales/messages.pot`` (the platform) and
``locales/content.pot`` (quizzes and exercise titles).
"""

from __future__ import annotations

from pathlib import Path

import click

from autograder.cli.exits import UsageProblem, report_problems
from autograder.core.errors import ContentError
from autograder.i18n import _, locales_dir
from autograder.i18n.glossary import TRANSLATIONS, check_all
from autograder.i18n.tools import compile_catalogs, extract, update
from content.course import course_root

_TARGETS = TRANSLATIONS


def _relative(path: Path) -> str:
    try:
        return str(path.relative_to(Path.cwd()))
    except ValueError:
        return str(path)


@click.group("i18n")
def i18n_cli() -> None:
    """Manage translations: extract strings, update and compile catalogs, check them."""


@i18n_cli.command("extract")
def extract_command() -> None:
    """Write locales/messages.pot and locales/content.pot from the sources (babel.cfg)."""
    try:
        for path in extract(course_root(), locales_dir()):
            click.echo(_("wrote {path}").format(path=_relative(path)))
    except ContentError as exc:
        raise UsageProblem(str(exc)) from None


@i18n_cli.command("update")
@click.option("--lang", "langs", multiple=True, type=click.Choice(_TARGETS),
              default=_TARGETS, show_default=True, help="Catalogs to update.")
def update_command(langs: tuple[str, ...]) -> None:
    """Merge the templates into locales/LANG/LC_MESSAGES/*.po (new strings left empty)."""
    try:
        for path in update(locales_dir(), langs):
            click.echo(_("updated {path}").format(path=_relative(path)))
    except ContentError as exc:
        raise UsageProblem(str(exc)) from None


@i18n_cli.command("compile")
def compile_command() -> None:
    """Compile every .po into a .mo beside it (optional: .po files load without it)."""
    try:
        for path in compile_catalogs(locales_dir()):
            click.echo(_("compiled {path}").format(path=_relative(path)))
    except ContentError as exc:
        raise UsageProblem(str(exc)) from None


@i18n_cli.command("check")
@click.option("--lang", "langs", multiple=True, type=click.Choice(_TARGETS),
              default=_TARGETS, show_default=True, help="Catalogs to check.")
def check_command(langs: tuple[str, ...]) -> None:
    """Every template string translated, not fuzzy, placeholders kept; no obsolete entries
    or template headers; the glossary followed in the catalogs and the exercise READMEs
    (file:line: message)."""
    report_problems(check_all(locales_dir(), langs, course_root()))
    click.echo(_("All catalogs are complete."))
