"""How every exercise proves its tests: grade its reference solution (several times,
beside other gradings), its starter, its other correct designs and its known-bad variants,
then check what each scored.

An exercise's project test declares ``PROOF = Proof(...)`` and imports the standard checks
below; ``tests/conftest.py`` grades the PROOF once per module (the ``graded`` fixture) and
parametrizes ``correct`` and ``mutant`` from it.
"""

from __future__ import annotations

import dataclasses
import os
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from autograder.core.exercise import find_exercise
from autograder.core.results import RunResult
from autograder.grading.run import grade

SUBMISSIONS = Path(__file__).parent / "submissions"
# Gradings at a time: two, as `grade-batch --jobs 2` on this 2-core machine.
JOBS = int(os.environ.get("AUTOGRADER_TEST_JOBS", "2"))


@dataclasses.dataclass(frozen=True)
class Proof:
    exercise: str
    correct: tuple[str, ...] = ()
    # Each known-bad variant, and the tests aimed at what it gets wrong.
    mutants: dict[str, frozenset[str]] = dataclasses.field(default_factory=dict)
    broken: tuple[str, ...] = ()
    repeats: int = 5
    jobs: int = JOBS

    def grade_all(self) -> dict[str, RunResult]:
        exercise = find_exercise(self.exercise)
        folder = SUBMISSIONS / self.exercise
        jobs: dict[str, Path | None] = {f"reference#{i}": None for i in range(self.repeats)}
        jobs["starter"] = exercise.starter
        for name in [*self.correct, *self.mutants, *self.broken]:
            jobs[name] = folder / name
        with ThreadPoolExecutor(max_workers=self.jobs) as pool:
            futures = {name: pool.submit(grade, exercise, path) for name, path in jobs.items()}
            return {name: future.result() for name, future in futures.items()}


def failed_tests(result: RunResult) -> set[str]:
    return set(failures(result))


def failures(result: RunResult) -> dict[str, str]:
    """What each lost test said, so a failed proof in CI says why and not only which."""
    return {t.name: f"{t.status}: {t.message}" for t in result.tests if t.status != "passed"}


def test_reference_scores_full_marks_every_time(graded, proof):
    results = [graded[f"reference#{i}"] for i in range(proof.repeats)]
    assert [r.grader_error for r in results] == [None] * proof.repeats
    assert all(r.score == r.max_score for r in results), [failures(r) for r in results]
    assert len({r.max_score for r in results}) == 1
    assert all(r.passed for r in results)


def test_starter_is_below_the_pass_mark(graded):
    result = graded["starter"]
    assert result.grader_error is None
    assert not result.passed
    assert result.score < result.max_score * result.pass_mark


def test_other_correct_designs_score_full_marks(graded, correct):
    result = graded[correct]
    assert result.grader_error is None
    assert result.score == result.max_score, failures(result)


def test_known_bad_variant_loses_the_test_aimed_at_it(graded, proof, mutant):
    result = graded[mutant]
    assert result.grader_error is None
    assert result.score < result.max_score
    assert proof.mutants[mutant] <= failed_tests(result), failures(result)
