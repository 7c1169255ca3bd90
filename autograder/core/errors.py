"""The two exception families: the student's failure, and our own fault."""

from __future__ import annotations


class StudentFailure(AssertionError):
    """The submission does not do what the exercise asks: a message and a hint to act on."""

    def __init__(self, message: str, hint: str = "") -> None:
        super().__init__(message)
        self.message = message
        self.hint = hint


class GraderError(Exception):
    """The autograder itself failed (our bug, the simulator, a missing dependency)."""
