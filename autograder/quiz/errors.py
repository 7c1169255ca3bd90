"""Errors the quiz and i18n commands print: one line naming the file, never a traceback.

Exit codes follow ``autograder.cli``: 0 when scoring completed, whatever the score; 1 when
lint found problems; 2 for bad input (a malformed or missing quiz, exercise, catalog or
answers file, an unknown quiz, a port in use).
"""

from __future__ import annotations

import click


class ContentFileError(click.ClickException):
    """A quiz, exercise, catalog or answers file is malformed, or a quiz id is unknown."""

    exit_code = 2


class LintFailed(click.ClickException):
    """Lint found problems (each already printed as ``file:line: message``)."""

    exit_code = 1


class ServeError(click.ClickException):
    """The quiz server could not bind its address."""

    exit_code = 2
