"""The exit codes of every ``autograder`` command, as click exceptions: each prints one
plain line (naming the file and line where there is one), never a traceback.

0 when the command completed (a grading or scoring, whatever the score); 1 when a check
(``quiz lint``, ``i18n check``, ``validate``) found problems, each already printed as
``file:line: message``; 2 for bad input (a malformed or missing file, an unknown exercise
or quiz, a port in use); 3 when the autograder itself failed.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import IO, Any

import click

from autograder.i18n import _, ngettext


class _Said(click.ClickException):
    """A click exception whose "Error:" prefix is in the active language (click's own is
    English whatever the language)."""

    def show(self, file: IO[Any] | None = None) -> None:
        click.echo(_("Error: {message}").format(message=self.format_message()), file=file,
                   err=file is None)


class ProblemsFound(_Said):
    """A check found problems (each already printed as ``file:line: message``)."""

    exit_code = 1


class UsageProblem(_Said):
    """Bad input from the user: one line naming the file and what is wrong."""

    exit_code = 2


class GraderFault(_Said):
    """The autograder failed: not the student's fault."""

    exit_code = 3


def report_problems(problems: Sequence[object]) -> None:
    """Print each problem (``file:line: message``) and end with :class:`ProblemsFound`
    if there are any; return quietly if there are none."""
    for problem in problems:
        click.echo(str(problem), err=True)
    if problems:
        raise ProblemsFound(ngettext("{count} problem found", "{count} problems found",
                                     len(problems)).format(count=len(problems)))
