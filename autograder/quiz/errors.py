"""Errors the quiz and i18n commands print: one line naming the file, never a traceback.

Exit codes: 1 a lint found problems (or a scored quiz did not pass), 3 a quiz, exercise or
catalog file is malformed or missing, 4 an answers file cannot be scored, 5 the server
could not start.
"""

from __future__ import annotations

import click


class ContentFileError(click.ClickException):
    """A quiz, exercise or catalog file is malformed, or a quiz id is unknown."""

    exit_code = 3


class AnswersFileError(click.ClickException):
    """An answers file is not valid JSON, answers another quiz or names unknown ids."""

    exit_code = 4


class LintFailed(click.ClickException):
    """Lint found problems (each already printed as ``file:line: message``)."""

    exit_code = 1


class ServeError(click.ClickException):
    """The quiz server could not bind its address."""

    exit_code = 5
