"""The exception families: a student's failure (an assertion, so pytest counts a failed
test, with a hint to act on), the user's bad input, our own fault (a disturbed grading
among it, with the users who disturbed it), and a content file's error, each caught apart."""

from __future__ import annotations

from pathlib import Path

import pytest

import content
from autograder.core import errors
from autograder.core.errors import (
    ContentError,
    Disturbed,
    GraderError,
    StudentFailure,
    UsageError,
)


def test_a_students_failure_is_a_failed_assertion_with_its_hint():
    failure = StudentFailure("no message on /cmd_vel within 5 s", hint="publish at 10 Hz")
    assert isinstance(failure, AssertionError)  # pytest: failed, not an error of the test
    assert (failure.message, failure.hint) == ("no message on /cmd_vel within 5 s",
                                               "publish at 10 Hz")
    assert str(failure) == "no message on /cmd_vel within 5 s"  # the hint is apart
    assert StudentFailure("bare").hint == ""


def test_a_disturbed_grading_is_ours_and_names_who_disturbed_it():
    disturbed = Disturbed("another user's node on domain 7", uids=(1001, 1002))
    assert isinstance(disturbed, GraderError)
    assert disturbed.uids == (1001, 1002)
    assert str(disturbed) == "another user's node on domain 7"


def test_the_content_error_is_the_content_layers_own():
    assert ContentError is content.ContentError
    error = ContentError(Path("exercise.yaml"), "must be between 0 and 1", line=4,
                         field="pass_mark")
    assert str(error) == "exercise.yaml:4: pass_mark: must be between 0 and 1"


@pytest.mark.parametrize("raised", [
    StudentFailure("wrong"), UsageError("no such exercise"), GraderError("our bug"),
    Disturbed("others on the domain", ()), ContentError("quiz.yaml", "bad")])
def test_each_family_is_caught_apart(raised):
    """Whoever catches one family (the CLI: a student's failure, exit 1; bad input, exit 2;
    ours, exit 3) never takes another's for it."""
    families = (StudentFailure, UsageError, GraderError, ContentError)
    caught = [family for family in families if isinstance(raised, family)]
    assert len(caught) == 1
    assert isinstance(raised, AssertionError) == isinstance(raised, StudentFailure)


def test_the_module_exports_the_families():
    assert sorted(errors.__all__) == ["ContentError", "Disturbed", "GraderError",
                                      "StudentFailure", "UsageError"]
    for name in errors.__all__:
        assert issubclass(getattr(errors, name), Exception)
