"""An exercise or quiz id nobody has: said as a missing name, with the likeliest one meant.

Exercise ids use underscores (``parameter_validation``) and quiz ids hyphens
(``rclpy-basics``); a student types one for the other, or a typo. The suggestion is the
known id equal to the name once ``-`` and ``_`` are one and case is ignored, else the
closest by :func:`difflib.get_close_matches`.
"""

from __future__ import annotations

import difflib
from collections.abc import Iterable
from pathlib import Path

from autograder.i18n import _
from content import ContentError


class UnknownName(ContentError):
    """No exercise or quiz has this name: not a malformed file, so said without a path
    (``path`` still says where it was looked for)."""

    def __init__(self, where: Path | str, message: str) -> None:
        super().__init__(where, message)

    def __str__(self) -> str:
        return self.message


def _plain(name: str) -> str:
    return name.strip().lower().replace("-", "_")


def suggest(name: str, known: Iterable[str]) -> str | None:
    """The known id ``name`` most likely meant, or None."""
    by_plain = {_plain(k): k for k in known}
    if _plain(name) in by_plain:
        return by_plain[_plain(name)]
    close = difflib.get_close_matches(_plain(name), list(by_plain), n=1, cutoff=0.6)
    return by_plain[close[0]] if close else None


def unknown_exercise(name: str, known: list[str], where: Path) -> UnknownName:
    """"No exercise named X", with the one meant or the list of them."""
    meant = suggest(name, known)
    if meant is not None:
        return UnknownName(where, _("No exercise named {name}. Did you mean {suggestion}?")
                           .format(name=name, suggestion=meant))
    return UnknownName(where, _("No exercise named {name}; the exercises are {known}.")
                       .format(name=name, known=", ".join(known) or "-"))


def unknown_quiz(name: str, known: list[str], where: Path) -> UnknownName:
    """"No quiz named X", with the one meant or the list of them."""
    meant = suggest(name, known)
    if meant is not None:
        return UnknownName(where, _("No quiz named {name}. Did you mean {suggestion}?")
                           .format(name=name, suggestion=meant))
    return UnknownName(where, _("No quiz named {name}; the quizzes are {known}.")
                       .format(name=name, known=", ".join(known) or "-"))


def unknown_item(name: str, exercises: list[str], quizzes: list[str],
                 where: Path) -> UnknownName:
    """"No exercise or quiz named X" (``grade-batch`` takes either), with the one meant."""
    meant = suggest(name, [*exercises, *quizzes])
    both = [suggest(meant, exercises), suggest(meant, quizzes)] if meant else []
    if len(both) == 2 and all(b is not None and _plain(b) == _plain(meant) for b in both):
        return UnknownName(where, _("No exercise or quiz named {name}. Did you mean the "
                                    "exercise {exercise} or the quiz {quiz}?").format(
            name=name, exercise=both[0], quiz=both[1]))
    if meant is not None:
        return UnknownName(where, _("No exercise or quiz named {name}. Did you mean "
                                    "{suggestion}?").format(name=name, suggestion=meant))
    return UnknownName(where, _("No exercise or quiz named {name}; the exercises are "
                                "{exercises}, the quizzes {quizzes}.").format(
        name=name, exercises=", ".join(exercises) or "-", quizzes=", ".join(quizzes) or "-"))
