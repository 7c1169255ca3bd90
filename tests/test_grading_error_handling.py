"""The error_handling exercise proves its tests: every submission graded end to end.

The reference solution scores 100% (five times, with other gradings running beside it:
the shutdown trials and the 60 s faulty run must not depend on load), the starter scores
below the pass mark, every other correct design (other executors, other ways to take a
signal) scores 100%, and each known-bad variant loses the tests aimed at it.  Variants
whose faults the public tests already show are graded on the public tests only, to keep
this module short; gradings run two at a time, on their own ROS domains.
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest

from autograder.exercise import find_exercise
from autograder.grading import grade
from autograder.results import RunResult

pytestmark = pytest.mark.slow

EXERCISE = find_exercise("error_handling")
SUBMISSIONS = Path(__file__).parent / "submissions" / "error_handling"

CORRECT = ["multithreaded", "spin_once_loop", "sigwait_future"]
# Each known-bad variant, the tests aimed at what it gets wrong, and whether the hidden
# tests are needed to show it.
MUTANTS = {
    "crashes_on_nan": ({"test_ignores_invalid_readings"}, False),
    "no_watchdog": ({"test_watchdog_stops"}, False),
    "floods_log": ({"test_log_not_flooded"}, True),
    "no_empty_scan_check": ({"test_rejects_malformed_scans"}, False),
    "exception_kills_node": ({"test_survives_exceptions"}, False),
    "traceback_on_sigint": ({"test_clean_exit_on_sigint", "test_clean_exit_on_sigterm"}, True),
}
REPEATS = 5


@pytest.fixture(scope="module")
def graded() -> dict[str, RunResult]:
    """Grade everything once, two gradings at a time (as `grade-batch --jobs 2` would)."""
    jobs: dict[str, tuple[Path | None, bool]] = {
        f"reference#{i}": (None, True) for i in range(REPEATS)}
    jobs["starter"] = (EXERCISE.starter, True)
    for name in CORRECT:
        jobs[name] = (SUBMISSIONS / name, True)
    for name, (_aimed, hidden) in MUTANTS.items():
        jobs[name] = (SUBMISSIONS / name, hidden)
    with ThreadPoolExecutor(max_workers=2) as pool:
        futures = {name: pool.submit(grade, EXERCISE, path, hidden=hidden)
                   for name, (path, hidden) in jobs.items()}
        return {name: future.result() for name, future in futures.items()}


def failed_tests(result: RunResult) -> set[str]:
    return {t.name for t in result.tests if t.status != "passed"}


def test_reference_scores_full_marks_every_time(graded):
    results = [graded[f"reference#{i}"] for i in range(REPEATS)]
    assert [r.grader_error for r in results] == [None] * REPEATS
    assert {(r.score, r.max_score) for r in results} == {(24, 24)}, \
        [failed_tests(r) for r in results]
    assert all(r.passed for r in results)


def test_starter_is_below_the_pass_mark(graded):
    result = graded["starter"]
    assert result.grader_error is None
    assert not result.passed
    assert 0 < result.score < result.max_score * result.pass_mark


@pytest.mark.parametrize("name", CORRECT)
def test_other_correct_designs_score_full_marks(graded, name):
    result = graded[name]
    assert result.grader_error is None
    assert result.score == result.max_score, failed_tests(result)


@pytest.mark.parametrize("name", list(MUTANTS))
def test_known_bad_variant_loses_the_tests_aimed_at_it(graded, name):
    result = graded[name]
    assert result.grader_error is None
    assert result.score < result.max_score
    assert MUTANTS[name][0] <= failed_tests(result), failed_tests(result)


def test_a_dead_or_silent_node_is_named_as_such(graded):
    """A node whose spinning thread died is told so, not blamed for each symptom."""
    by_name = {t.name: t for t in graded["crashes_on_nan"].tests}
    message = by_name["test_ignores_invalid_readings"].message
    assert "stopped publishing on cmd_vel" in message
    assert "ValueError" in message or "Traceback" in message


def test_shutdown_failure_shows_the_traceback(graded):
    by_name = {t.name: t for t in graded["traceback_on_sigint"].tests}
    message = by_name["test_clean_exit_on_sigint"].message
    assert "trial 1 of 3" in message
    assert "Traceback" in message
