"""The parameter_validation exercise proves its tests: every submission graded end to end.

The reference solution scores 100% (five times, with other gradings running beside it),
the starter scores below the pass mark, every other correct design scores 100%, each
known-bad variant loses the test aimed at it, and broken programs get a score and a plain
message.  Gradings run two at a time, on their own ROS domains.
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest

from autograder.exercise import find_exercise
from autograder.grading import grade
from autograder.results import RunResult

pytestmark = pytest.mark.slow

EXERCISE = find_exercise("parameter_validation")
SUBMISSIONS = Path(__file__).parent / "submissions" / "parameter_validation"

CORRECT = ["descriptor_ranges", "pre_post_callbacks", "read_each_message", "multithreaded"]
# Each known-bad variant, and the tests aimed at what it gets wrong.
MUTANTS = {
    "no_linear_clamp": {"test_clamps_linear", "test_speed_stays_under_limit"},
    "no_angular_clamp": {"test_clamps_angular"},
    "accepts_out_of_range": {"test_refuses_out_of_range"},
    "accepts_empty_name": {"test_refuses_empty_robot_name"},
    "silent_refusal": {"test_refuses_out_of_range", "test_refuses_empty_robot_name"},
    "ignores_invalid_override": {"test_invalid_override_exits"},
    "stale_limits": {"test_accepted_value_applies"},
    "double_publish": {"test_one_output_per_input"},
    "keeps_other_fields": {"test_other_fields_zero"},
}
BROKEN = ["syntax_error", "crash_at_start", "never_spins", "wrong_node_name"]
REPEATS = 5


@pytest.fixture(scope="module")
def graded() -> dict[str, RunResult]:
    """Grade everything once, two gradings at a time (as `grade-batch --jobs 2` would)."""
    jobs: dict[str, Path | None] = {f"reference#{i}": None for i in range(REPEATS)}
    jobs["starter"] = EXERCISE.starter
    for name in [*CORRECT, *MUTANTS, *BROKEN]:
        jobs[name] = SUBMISSIONS / name
    with ThreadPoolExecutor(max_workers=2) as pool:
        futures = {name: pool.submit(grade, EXERCISE, path) for name, path in jobs.items()}
        return {name: future.result() for name, future in futures.items()}


def failed_tests(result: RunResult) -> set[str]:
    return {t.name for t in result.tests if t.status != "passed"}


def test_reference_scores_full_marks_every_time(graded):
    results = [graded[f"reference#{i}"] for i in range(REPEATS)]
    assert [r.grader_error for r in results] == [None] * REPEATS
    assert {(r.score, r.max_score) for r in results} == {(13, 13)}, \
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
def test_known_bad_variant_loses_the_test_aimed_at_it(graded, name):
    result = graded[name]
    assert result.grader_error is None
    assert result.score < result.max_score
    assert MUTANTS[name] <= failed_tests(result)


def test_syntax_error_is_named_with_its_line(graded):
    result = graded["syntax_error"]
    assert result.grader_error is None
    assert result.score == 0
    assert all("velocity_governor.py, line" in t.message for t in result.tests)


def test_crash_at_start_scores_zero_with_its_traceback(graded):
    result = graded["crash_at_start"]
    assert result.grader_error is None
    assert result.score == 0
    message = result.tests[0].message
    assert "exited with status 1 before its node 'velocity_governor' appeared" in message
    assert "Traceback" in message


def test_wrong_node_name_is_reported_with_the_names_seen(graded):
    result = graded["wrong_node_name"]
    # Only the invalid-override test, which needs no node name, can pass.
    assert failed_tests(result) >= {t.name for t in result.tests} - {
        "test_invalid_override_exits"}
    assert "No node named 'velocity_governor'" in result.tests[0].message
    assert "governor" in result.tests[0].message


def test_node_that_never_spins_fails_what_needs_spinning(graded):
    result = graded["never_spins"]
    assert result.grader_error is None
    assert not result.passed
    by_name = {t.name: t for t in result.tests}
    for name in ("test_clamps_linear", "test_refuses_out_of_range"):
        assert by_name[name].score == 0
        assert "spinning" in by_name[name].hint + by_name[name].message
