"""The timer_sync exercise proves its tests: every submission graded end to end.

The reference solution is the chapter's design (a MultiThreadedExecutor, the planner
timer in a callback group of its own) and scores 100% five times, with other gradings
running beside it; the starter scores below the pass mark; other correct designs (a
worker thread, an awaited future, one reentrant group) score 100%; each known-bad variant
loses the tests aimed at what it gets wrong.  Gradings run two at a time.
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest

from autograder.exercise import find_exercise
from autograder.grading import grade
from autograder.results import RunResult

pytestmark = pytest.mark.slow

EXERCISE = find_exercise("timer_sync")
SUBMISSIONS = Path(__file__).parent / "submissions" / "timer_sync"

CORRECT = ["worker_thread", "async_future", "reentrant_lock"]
# Each known-bad variant, and the tests aimed at what it gets wrong.
MUTANTS = {
    "single_threaded": {"test_control_rate", "test_control_while_planning", "test_plan_rate",
                        "test_rates_at_half_speed"},
    "shared_group": {"test_control_rate", "test_control_while_planning"},
    "wall_clock": {"test_rates_at_half_speed"},
    "wrong_status": {"test_status_counts"},
    "no_plan_publish": {"test_plan_rate"},
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
    """The reference is the chapter's MultiThreadedExecutor with a planner group of its own."""
    results = [graded[f"reference#{i}"] for i in range(REPEATS)]
    assert [r.grader_error for r in results] == [None] * REPEATS
    assert {(r.score, r.max_score) for r in results} == {(14, 14)}, \
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


def test_frozen_clock_is_explained(graded):
    """A single-threaded node freezes ROS time; the message says so and names the fix."""
    result = graded["single_threaded"]
    by_name = {t.name: t for t in result.tests}
    test = by_name["test_control_rate"]
    assert "stopped" in test.message
    assert "/clock" in test.hint and "MultiThreadedExecutor" in test.hint
