"""The ai_bridge exercise proves its tests: every submission graded end to end.

The reference agent scores 100% in all three worlds (five times, with other gradings
running beside it), the starter scores below the pass mark, an agent built another way
(an occupancy grid and A*) scores 100%, and each known-bad agent loses the tests aimed at
it, with partial credit for the share of the way it covered.
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor
from fractions import Fraction
from pathlib import Path

import pytest

from autograder.exercise import find_exercise
from autograder.grading import grade
from autograder.results import RunResult

pytestmark = pytest.mark.slow

EXERCISE = find_exercise("ai_bridge")
SUBMISSIONS = Path(__file__).parent / "submissions" / "ai_bridge"

CORRECT = ["grid_planner"]
# Each known-bad agent, and the tests aimed at what it gets wrong.
MUTANTS = {
    "ignores_obstacles": {"test_obstacles_reaches_goal", "test_corridor_reaches_goal"},
    "never_reports": {"test_open_room_reports_arrival"},
    "stops_short": {"test_open_room_reaches_goal", "test_obstacles_reaches_goal",
                    "test_corridor_reaches_goal"},
    "wanders": {"test_open_room_efficient_path"},
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


def test_reference_scores_full_marks_every_time(graded):
    results = [graded[f"reference#{i}"] for i in range(REPEATS)]
    assert [r.grader_error for r in results] == [None] * REPEATS
    assert {(r.score, r.max_score) for r in results} == {(14, 14)}, \
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
    assert MUTANTS[name] <= failed_tests(result), failed_tests(result)


def test_progress_earns_partial_credit(graded):
    """Stopping 0.6 m short earns the share of the way covered, and says so."""
    by_name = {t.name: t for t in graded["stops_short"].tests}
    for name in ("test_open_room_reaches_goal", "test_obstacles_reaches_goal",
                 "test_corridor_reaches_goal"):
        test = by_name[name]
        assert test.status == "failed"
        assert Fraction(1, 2) * test.max_score < test.score < test.max_score
        assert "of the way" in test.message


def test_a_collision_is_named(graded):
    by_name = {t.name: t for t in graded["ignores_obstacles"].tests}
    message = by_name["test_corridor_reaches_goal"].message
    assert "hit wall" in message
    assert by_name["test_corridor_reaches_goal"].score < 1
