"""The callback_groups exercise proves its tests: every submission graded end to end.

The reference solution is the chapter's design (a MultiThreadedExecutor; the service in
a callback group of its own waits on a condition that the scan callback, in another
group, notifies) and scores 100% five times, with other gradings running beside it; the
starter scores below the pass mark; other correct designs (requests served one at a
time, an awaited future on one thread) score 100%; each known-bad variant loses the
tests aimed at what it gets wrong, and a node spinning Jazzy's EventsExecutor (which runs
no callback, burns a core and ignores SIGINT) still ends with a score.
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest

from autograder.exercise import find_exercise
from autograder.grading import grade
from autograder.results import RunResult

pytestmark = pytest.mark.slow

EXERCISE = find_exercise("callback_groups")
SUBMISSIONS = Path(__file__).parent / "submissions" / "callback_groups"

CORRECT = ["serial_service", "async_future"]
# Each known-bad variant, and the tests aimed at what it gets wrong.
MUTANTS = {
    "old_scan": {"test_answer_uses_newer_scan", "test_no_fresh_scan"},
    "deadlock": {"test_open_space", "test_concurrent_requests", "test_never_deadlocks"},
    "shared_group": {"test_open_space", "test_concurrent_requests"},
    "events_executor": {"test_node_starts", "test_open_space", "test_never_deadlocks"},
    "wrong_threshold": {"test_box_ahead"},
    "ignores_invalid_readings": {"test_ignores_invalid_readings"},
    "no_rate_topic": {"test_scan_rate"},
}
REPEATS = 5


@pytest.fixture(scope="module")
def graded() -> dict[str, RunResult]:
    """Grade everything once, two gradings at a time (as `grade-batch --jobs 2` would)."""
    jobs: dict[str, Path | None] = {f"reference#{i}": None for i in range(REPEATS)}
    jobs["starter"] = EXERCISE.starter
    for name in [*CORRECT, *MUTANTS]:
        jobs[name] = SUBMISSIONS / name
    with ThreadPoolExecutor(max_workers=2) as pool:
        futures = {name: pool.submit(grade, EXERCISE, path) for name, path in jobs.items()}
        return {name: future.result() for name, future in futures.items()}


def failed_tests(result: RunResult) -> set[str]:
    return {t.name for t in result.tests if t.status != "passed"}


def test_chapter_design_scores_full_marks_every_time(graded):
    """The reference is the chapter's MultiThreadedExecutor with the service in its own group."""
    results = [graded[f"reference#{i}"] for i in range(REPEATS)]
    assert [r.grader_error for r in results] == [None] * REPEATS
    assert {(r.score, r.max_score) for r in results} == {(13, 13)}, \
        [failed_tests(r) for r in results]


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
def test_known_bad_variant_loses_the_test_aimed_at_it(graded, name):
    result = graded[name]
    assert result.grader_error is None
    assert result.score < result.max_score
    assert MUTANTS[name] <= failed_tests(result), failed_tests(result)


def test_events_executor_ends_with_a_score_and_a_reason(graded):
    """It spins a core without running a callback and ignores SIGINT: stopped, scored,
    explained (the world slows to its CPU budget per tick, so its waits end on the wall)."""
    result = graded["events_executor"]
    assert result.grader_error is None and not result.data["timed_out"]
    assert result.score == 0
    assert all(t.status in ("failed", "skipped") and t.message for t in result.tests)
    assert result.execution_time < EXERCISE.time_limit / 2


def test_old_scan_is_told_why(graded):
    result = graded["old_scan"]
    by_name = {t.name: t for t in result.tests}
    assert "before any scan newer than the request existed" in \
        by_name["test_answer_uses_newer_scan"].message
