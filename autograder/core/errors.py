"""The exception families: the student's failure, our own fault, the user's bad input (a
malformed content file among it).

:class:`ContentError` (``path:line: field: message``) belongs to the content layer
(:mod:`content`), below the simulator and the autograder; it is listed here with the other
two families.
"""

from __future__ import annotations

from content import ContentError

__all__ = ["ContentError", "Disturbed", "GraderError", "StudentFailure", "UsageError"]


class StudentFailure(AssertionError):
    """The submission does not do what the exercise asks: a message and a hint to act on."""

    def __init__(self, message: str, hint: str = "") -> None:
        super().__init__(message)
        self.message = message
        self.hint = hint


class UsageError(Exception):
    """Bad input from the user (a missing file, an unknown exercise): one line saying what
    is wrong, the user's to fix. The CLI ends with exit status 2."""


class GraderError(Exception):
    """The autograder itself failed (our bug, the simulator, a missing dependency)."""


class Disturbed(GraderError):
    """Programs of other users (``uids``) were on the grading's ROS domain: what the test
    saw proves nothing, about the student or anyone. The grading is done again once they
    are gone."""

    def __init__(self, message: str, uids: tuple[int, ...]) -> None:
        super().__init__(message)
        self.uids = uids
